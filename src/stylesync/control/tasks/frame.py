"""Tasks on one frame of the character: its orientation (the pelvis) or its position (a foot, a hand).

Both are PD laws in world axes, ``ẍ* = kp e + kd (ẋ_ref - ẋ)`` with ``e`` the position error [m] or the rotation
vector of ``R_ref Rᵀ`` [rad], and rows ``J q̈ = ẍ* - J̇ q̇`` (LOCAL_WORLD_ALIGNED Jacobian and drift).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from stylesync import rotations as rot
from stylesync.control.tasks.base import Task, TaskRows
from stylesync.model.character_model import CharacterModel


class FramePositionTask(Task):
    """The frame's origin follows a world target; ``axes`` selects rows (e.g. only z for a foot pressed down)."""

    def __init__(self, name: str, frame: str, kp: float, kd: float, weight: float,
                 axes: tuple[int, ...] = (0, 1, 2)):
        self.name = name
        self.frame = frame
        self.kp, self.kd = kp, kd  # [1/s², 1/s]
        self.weight = weight
        self.axes = np.array(axes)
        self.target_world = np.zeros(3)  # [m]
        self.target_vel_world = np.zeros(3)  # [m/s]

    def rows(self, model: CharacterModel) -> TaskRows:
        f = self._frame_id(model)
        jac = model.frame_jacobian(f)[self.axes]
        pos, vel = model.frame_placement(f).translation, model.frame_velocity(f)[:3]
        accel = self.kp * (self.target_world - pos) + self.kd * (self.target_vel_world - vel)
        target = accel[self.axes] - model.frame_drift(f)[self.axes]
        return TaskRows(jac, target, np.full(len(self.axes), self.weight))


class FrameOrientationTask(Task):
    """The frame's canonical orientation follows a target: ``α* = kp · log(q_ref q⁻¹) - kd ω`` (world axes),
    with ``gain_scale`` per world axis (e.g. a different gain about the vertical). ``weight`` is per row (3,)."""

    def __init__(self, name: str, frame: str, kp: float, kd: float, weight: np.ndarray | float,
                 q_frame_canonical_wxyz: np.ndarray):
        self.name = name
        self.frame = frame
        self.kp, self.kd = kp, kd  # [1/s², 1/s]
        self.weight = np.broadcast_to(np.asarray(weight, dtype=float), (3,)).copy()
        self.gain_scale = np.ones(3)
        self.target_quat_wxyz = np.array([1.0, 0.0, 0.0, 0.0])  # canonical orientation (identity: upright, +x)
        self.error_rotvec = np.zeros(3)  # the last error [rad], world axes
        # The frame's canonical orientation = its model orientation times this (the model's axes are Y-up).
        self._r_frame_canonical = rot.matrix_from_quat(q_frame_canonical_wxyz)

    def rows(self, model: CharacterModel) -> TaskRows:
        f = self._frame_id(model)
        r = model.frame_placement(f).rotation @ self._r_frame_canonical
        self.error_rotvec = pin.log3(rot.matrix_from_quat(self.target_quat_wxyz) @ r.T)
        omega = model.frame_velocity(f)[3:]
        accel = self.gain_scale * (self.kp * self.error_rotvec - self.kd * omega)
        return TaskRows(model.frame_jacobian(f)[3:], accel - model.frame_drift(f)[3:], self.weight)

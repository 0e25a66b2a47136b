"""PID joint controller (Sec. 6.1, Eq. 13), run at the physics rate.

Eq. 13 is read with continuous-time gains (Table 3): τ = Kp e + Ki ∫e dt + Kd ė, e the joint error. For ball
joints e is the rotation vector of ``q_f^{-1} ⊗ q_d`` (child frame, the frame the torque acts in); for hinges the
angle difference. The derivative uses the measured joint velocity against the reference's velocity (estimated
at the control rate), which equals ė without the spikes a held 133 Hz reference would put into a finite
difference at 600 Hz. The sum is clamped (anti-windup). Table 3's gains are used as printed: the controller
evaluates this feedback implicitly (stable_pd.py), which keeps them stable on the light links at 600 Hz.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.config import JacobianTransposeConfig, pid_group
from stylesync.model.character import JOINTS, JointKind

IS_BALL = np.array([j.kind is JointKind.BALL for j in JOINTS])
_BALL = np.flatnonzero(IS_BALL)
_HINGE = np.flatnonzero(~IS_BALL)


def gain_arrays(cfg: JacobianTransposeConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    kp = np.array([cfg.pid[pid_group(j.name)].kp for j in JOINTS])
    ki = np.array([cfg.pid[pid_group(j.name)].ki for j in JOINTS])
    kd = np.array([cfg.pid[pid_group(j.name)].kd for j in JOINTS])
    return kp, ki, kd


def joint_error(q_current: np.ndarray, q_desired: np.ndarray) -> np.ndarray:
    """(..., n_joints, 3) error of (..., n_joints, 4) joint values: child-frame rotation vector for ball joints,
    angle in column 0 for hinges [rad]."""
    # Every row as a quaternion at once (a control-tick cost): a hinge's row (angle, 0, 0, 0) gives a zero
    # rotation vector, and then its angle difference.
    e = rot.batch_rotvec(rot.batch_multiply(rot.batch_conjugate(q_current.reshape(-1, 4)),
                                            q_desired.reshape(-1, 4))).reshape(*q_current.shape[:-1], 3)
    e[..., _HINGE, 0] = q_desired[..., _HINGE, 0] - q_current[..., _HINGE, 0]
    return e


def reference_velocity(q_previous: np.ndarray, q_current: np.ndarray, dt_s: float) -> np.ndarray:
    """(n_joints, 3) joint velocity of a reference between two control ticks: child-frame angular velocity for
    ball joints, rate in column 0 for hinges [rad/s]."""
    return joint_error(q_previous, q_current) / dt_s


class JointPid:
    def __init__(self, cfg: JacobianTransposeConfig, dt_s: float):
        kp, ki, kd = gain_arrays(cfg)
        self.kp = np.repeat(kp[:, None], 3, axis=1)  # (n_joints, 3) per DOF
        self.ki = np.repeat(ki[:, None], 3, axis=1)
        self.kd = np.repeat(kd[:, None], 3, axis=1)
        self.dt_s = dt_s
        self.integral_limit = cfg.integral_limit_rad_s
        self.integral = np.zeros((len(JOINTS), 3))

    def reset(self) -> None:
        self.integral[:] = 0.0

    def __call__(self, q_current: np.ndarray, qdot_current: np.ndarray, q_desired: np.ndarray,
                 qdot_desired: np.ndarray, gain_scale: np.ndarray | None = None,
                 predict_dt_s: float = 0.0) -> np.ndarray:
        """Eq. 13. With ``predict_dt_s`` the position error is taken at the predicted next step, e - dt q̇
        (the explicit part of the stable PD, see stable_pd.py)."""
        e = joint_error(q_current, q_desired)  # Eq. 13, q_d(t+1) - q_f(t)
        self.integral = np.clip(self.integral + e * self.dt_s, -self.integral_limit, self.integral_limit)
        e_next = e - predict_dt_s * qdot_current
        tau = self.kp * e_next + self.ki * self.integral + self.kd * (qdot_desired - qdot_current)
        if gain_scale is not None:
            tau *= gain_scale[:, None]
        return tau

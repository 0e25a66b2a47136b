"""Operator responses scripted on the human model, for the experiments that no recorded clip covers (the push
recoveries of Sec. 7.4.2, the squat of Sec. 7.4.5).

Each response is a function of time giving the pelvis position and the canonical joint rotations of a
:class:`HumanModel`; the legs are placed by a two-link inverse kinematics in the sagittal plane so that the feet
are where the script puts them (on the floor when planted). The result goes through the same Kinect-like sensor
model as the built-in operator (`builtin_operator.sensed`: 16 Hz, noise, jitter, fixed seed).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.sources.frame import OperatorFrame
from stylesync.sources.human_model import HumanModel

_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])


def sagittal_leg(human: HumanModel, ankle_rel_hip_m: np.ndarray) -> dict[str, float]:
    """Hip, knee and ankle pitch [rad] (rotations about +y, canonical axes; + moves the distal end backward) that
    put the ankle at ``(dx, dz)`` from the hip (x forward, z up), knee flexed, foot level."""
    dx, dz = float(ankle_rel_hip_m[0]), float(ankle_rel_hip_m[1])
    T, S = human.thigh_m, human.shank_m
    d = min(float(np.hypot(dx, dz)), T + S - 1e-6)
    knee = float(np.arccos(np.clip((d * d - T * T - S * S) / (2 * T * S), -1.0, 1.0)))
    lean = float(np.arctan2(-dx, -dz))  # leg line from the vertical, + when the ankle is behind the hip
    hip = lean - float(np.arctan2(S * np.sin(knee), T + S * np.cos(knee)))
    return {"hip": hip, "knee": knee, "ankle": -(hip + knee)}


def pose_frame(human: HumanModel, t_s: float, pelvis_world: np.ndarray, ankles_world: dict[str, np.ndarray],
               extra: dict[str, np.ndarray] | None = None) -> OperatorFrame:
    """A frame with the pelvis at ``pelvis_world`` (facing +x) and each ankle at ``ankles_world[side]``, plus any
    other canonical joint rotations in ``extra``. Each leg is rolled about the forward axis at the hip (and back
    at the ankle, the foot level) so that its ankle is at its lateral position, then bent in the rolled plane by
    `sagittal_leg`; an ankle straight below its hip has no roll."""
    quats: dict[str, np.ndarray] = {"PELVIS": rot.IDENTITY_WXYZ}
    hip_half_width = _hip_half_width(human)
    for side in ("left", "right"):
        rel = ankles_world[side] - pelvis_world
        dy = float(rel[1]) - (hip_half_width if side == "left" else -hip_half_width)  # ankle left of its hip [m]
        roll = float(np.arctan2(dy, -float(rel[2])))  # + puts the ankle to the left [rad]
        leg = sagittal_leg(human, np.array([rel[0], -np.hypot(dy, rel[2]) if dy else rel[2]]))
        S = side.upper()
        hip, ankle = rot.quat_from_rotvec(_Y * leg["hip"]), rot.quat_from_rotvec(_Y * leg["ankle"])
        if dy:
            hip = rot.multiply(rot.quat_from_rotvec(_X * roll), hip)
            ankle = rot.multiply(ankle, rot.quat_from_rotvec(_X * -roll))
        quats[f"HIP_{S}"] = hip
        quats[f"KNEE_{S}"] = rot.quat_from_rotvec(_Y * leg["knee"])
        quats[f"ANKLE_{S}"] = ankle
    quats.update(extra or {})
    return human.frame_from_pose(t_s, pelvis_world, quats)


def _hip_half_width(human: HumanModel) -> float:
    """Lateral offset of the left hip from the pelvis [m] (the right one's is its negative)."""
    return float(next(s for s in human.segments if s.name == "thigh_left").offset_in_parent[1])


def standing_ankles(human: HumanModel) -> dict[str, np.ndarray]:
    hw = _hip_half_width(human)
    return {"left": np.array([0.0, hw, human.ankle_height_m]), "right": np.array([0.0, -hw, human.ankle_height_m])}

"""The operator frame: what every source produces (Sec. 4.1).

Canonical operator skeleton: the 32 joints of the Azure Kinect Body Tracking SDK, in its order. World frame z up,
x forward, y left, metres. Orientation at a joint = world orientation (w, x, y, z) of the body segment that the
joint drives (PELVIS: pelvis, SPINE_CHEST: torso, NECK: head, HIP_*: thigh, KNEE_*: shank, ANKLE_*: foot,
SHOULDER_*: upper arm, ELBOW_*: forearm), expressed so that the identity is the rest pose: standing straight,
facing +x, arms hanging down, feet pointing forward. Confidence 0 means "not tracked" (position and orientation
must then be ignored).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

K4ABT_JOINTS: tuple[str, ...] = (
    "PELVIS", "SPINE_NAVEL", "SPINE_CHEST", "NECK", "CLAVICLE_LEFT", "SHOULDER_LEFT", "ELBOW_LEFT", "WRIST_LEFT",
    "HAND_LEFT", "HANDTIP_LEFT", "THUMB_LEFT", "CLAVICLE_RIGHT", "SHOULDER_RIGHT", "ELBOW_RIGHT", "WRIST_RIGHT",
    "HAND_RIGHT", "HANDTIP_RIGHT", "THUMB_RIGHT", "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "FOOT_LEFT", "HIP_RIGHT",
    "KNEE_RIGHT", "ANKLE_RIGHT", "FOOT_RIGHT", "HEAD", "NOSE", "EYE_LEFT", "EAR_LEFT", "EYE_RIGHT", "EAR_RIGHT",
)
JOINT_INDEX: dict[str, int] = {n: i for i, n in enumerate(K4ABT_JOINTS)}
N_JOINTS = len(K4ABT_JOINTS)


def J(name: str) -> int:
    """Index of a canonical joint."""
    return JOINT_INDEX[name]


@dataclass
class OperatorFrame:
    timestamp_s: float
    joint_pos_world: np.ndarray  # (32, 3) [m]
    joint_quat_wxyz: np.ndarray  # (32, 4) canonical segment orientations
    confidence: np.ndarray  # (32,) in [0, 1]
    com_world: np.ndarray | None = None  # (3,) operator COM when the source knows it (Eq. 6) [m]
    point_cloud_world: np.ndarray | None = None  # (n, 3) body point cloud [m], optional
    extras: dict[str, float] = field(default_factory=dict)

    def pos(self, name: str) -> np.ndarray:
        return self.joint_pos_world[JOINT_INDEX[name]]

    def quat(self, name: str) -> np.ndarray:
        return self.joint_quat_wxyz[JOINT_INDEX[name]]

    def is_finite(self) -> bool:
        return bool(np.all(np.isfinite(self.joint_pos_world)) and np.all(np.isfinite(self.joint_quat_wxyz)))

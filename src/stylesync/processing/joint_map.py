"""Joint map from the operator skeleton to the character (Sec. 4.1, Fig. 3a).

Character joint rotations are the operator's segment orientations relative to their parent segment. The
sensor's hands, hand tips, thumbs, clavicles, navel and face points are ignored (unreliable or without a
character DOF, the red-dotted joints of Fig. 3a); the character's ankles come from the pose optimisation
(Sec. 5.3), not from the sensor. Hinges (knees, elbows) keep the twist of the relative rotation about the hinge
axis, clamped to the character's range.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.sources.frame import JOINT_INDEX, OperatorFrame

# character joint -> (operator child joint, operator parent joint)
JOINT_MAP: dict[str, tuple[str, str]] = {
    "chest": ("SPINE_CHEST", "PELVIS"),
    "neck": ("NECK", "SPINE_CHEST"),
    "right_hip": ("HIP_RIGHT", "PELVIS"),
    "right_knee": ("KNEE_RIGHT", "HIP_RIGHT"),
    "right_shoulder": ("SHOULDER_RIGHT", "SPINE_CHEST"),
    "right_elbow": ("ELBOW_RIGHT", "SHOULDER_RIGHT"),
    "left_hip": ("HIP_LEFT", "PELVIS"),
    "left_knee": ("KNEE_LEFT", "HIP_LEFT"),
    "left_shoulder": ("SHOULDER_LEFT", "SPINE_CHEST"),
    "left_elbow": ("ELBOW_LEFT", "SHOULDER_LEFT"),
}
# Operator joints whose orientation the pipeline reads (world, canonical): the root and the segments above.
TRACKED_ORIENTATIONS: tuple[str, ...] = (
    "PELVIS", "SPINE_CHEST", "NECK", "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "HIP_RIGHT", "KNEE_RIGHT",
    "ANKLE_RIGHT", "SHOULDER_LEFT", "ELBOW_LEFT", "SHOULDER_RIGHT", "ELBOW_RIGHT",
)
TRACKED_POSITIONS: tuple[str, ...] = (
    "PELVIS", "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "FOOT_LEFT", "HIP_RIGHT", "KNEE_RIGHT", "ANKLE_RIGHT",
    "FOOT_RIGHT", "SPINE_CHEST", "NECK", "HEAD", "SHOULDER_LEFT", "ELBOW_LEFT", "WRIST_LEFT", "SHOULDER_RIGHT",
    "ELBOW_RIGHT", "WRIST_RIGHT",
)
HINGE_AXIS_CANONICAL = np.array([0.0, -1.0, 0.0])  # knee and elbow axis (model z) in canonical axes
HINGE_RANGE_RAD = {"knee": (-np.pi, 0.0), "elbow": (0.0, np.pi)}  # URDF joint limits


def local_rotations(world_quats: dict[str, np.ndarray], joints: tuple[str, ...],
                    parents: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """(len(joints), 4) local rotations conj(q_parent) ⊗ q_child of the joint map's pairs, in one batched product.
    ``parents``: world orientations to use instead of a joint's mapped parent (e.g. the chest against a level root)."""
    parents = parents or {}
    q_parent = np.array([parents[j] if j in parents else world_quats[JOINT_MAP[j][1]] for j in joints])
    q_child = np.array([world_quats[JOINT_MAP[j][0]] for j in joints])
    return rot.batch_multiply(rot.batch_conjugate(q_parent), q_child)


def hinge_angle(q_local: np.ndarray, joint: str) -> float:
    lo, hi = HINGE_RANGE_RAD[joint.split("_")[1]]
    return min(max(rot.twist_angle(q_local, HINGE_AXIS_CANONICAL), lo), hi)


def tracked_arrays(frame: OperatorFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Orientations (n, 4), positions (m, 3) and their confidences read from a frame."""
    qi = [JOINT_INDEX[n] for n in TRACKED_ORIENTATIONS]
    pi = [JOINT_INDEX[n] for n in TRACKED_POSITIONS]
    return (frame.joint_quat_wxyz[qi], frame.joint_pos_world[pi], frame.confidence[qi], frame.confidence[pi])

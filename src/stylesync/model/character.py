"""Description of the simulated character: the DeepMimic humanoid shipped in pybullet_data (Sec. 7.1, Table 2).

Engine-independent: joint names, kinds, parents, torque limits. The URDF is Y-up; our world is z-up, x forward,
y left. The model's link frames equal the base frame in the rest pose (all joint origins have rpy = 0), and the
base is loaded rotated by ``Q_WORLD_MODEL`` (+90 deg about x). A *canonical segment orientation* is the world
orientation of a link with that constant rotation removed, so that in the rest pose (standing straight, arms
down, feet forward along +x) every canonical segment orientation is the identity.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from stylesync import rotations as rot

URDF_PATH_IN_PYBULLET_DATA = "humanoid/humanoid.urdf"
URDF_GLOBAL_SCALING = 0.25  # the URDF is authored at 4x scale; DeepMimic loads it at 0.25
CHARACTER_HEIGHT_M = 1.62  # Sec. 7.1
CHARACTER_MASS_KG = 45.0  # Sec. 7.1
STANDING_ROOT_HEIGHT_M = 0.8814  # pelvis origin height with straight legs and feet flat [m] (hips at its height)

# World orientation of the model's frame: +90 deg about x maps the URDF's +y (up) to world +z.
Q_WORLD_MODEL = rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), np.pi / 2)


class JointKind(Enum):
    BALL = "ball"  # 3 DOF, spherical; torque and velocity in the child link frame
    HINGE = "hinge"  # 1 DOF, revolute about its axis


@dataclass(frozen=True)
class JointSpec:
    name: str
    kind: JointKind
    parent: str  # parent link name; "root" is the pelvis
    torque_limit_nm: float  # per-axis torque limit [N·m], DeepMimic humanoid3d character file
    axis_in_model: tuple[float, float, float] = (0.0, 0.0, 1.0)  # hinge axis in the child frame (model axes)


# Actuated joints in URDF order. Torque limits follow the DeepMimic humanoid3d character definition
# (chest 200, neck 50, hip 200, knee 150, ankle 90, shoulder 100, elbow 60 N·m).
JOINTS: tuple[JointSpec, ...] = (
    JointSpec("chest", JointKind.BALL, "root", 200.0),
    JointSpec("neck", JointKind.BALL, "chest", 50.0),
    JointSpec("right_hip", JointKind.BALL, "root", 200.0),
    JointSpec("right_knee", JointKind.HINGE, "right_hip", 150.0),
    JointSpec("right_ankle", JointKind.BALL, "right_knee", 90.0),
    JointSpec("right_shoulder", JointKind.BALL, "chest", 100.0),
    JointSpec("right_elbow", JointKind.HINGE, "right_shoulder", 60.0),
    JointSpec("left_hip", JointKind.BALL, "root", 200.0),
    JointSpec("left_knee", JointKind.HINGE, "left_hip", 150.0),
    JointSpec("left_ankle", JointKind.BALL, "left_knee", 90.0),
    JointSpec("left_shoulder", JointKind.BALL, "chest", 100.0),
    JointSpec("left_elbow", JointKind.HINGE, "left_shoulder", 60.0),
)
JOINT_NAMES: tuple[str, ...] = tuple(j.name for j in JOINTS)

# Generalised velocity layout used for the joint-space inertia: the floating root (linear, then angular velocity,
# world frame) and then each joint's DOFs in JOINTS order (ball: 3 child-frame axes, hinge: 1).
ROOT_DOFS = 6
JOINT_DOF_COUNT: tuple[int, ...] = tuple(3 if j.kind is JointKind.BALL else 1 for j in JOINTS)
JOINT_DOF_START: tuple[int, ...] = tuple(int(x) for x in np.cumsum((0,) + JOINT_DOF_COUNT[:-1]))
N_JOINT_DOFS = int(sum(JOINT_DOF_COUNT))
N_DOFS = ROOT_DOFS + N_JOINT_DOFS  # generalised velocities of the floating character
JOINT_BY_NAME: dict[str, JointSpec] = {j.name: j for j in JOINTS}

# All rigid links with mass, in URDF order ("root" is the pelvis; wrists are fixed hands).
LINK_NAMES: tuple[str, ...] = (
    "root", "chest", "neck", "right_hip", "right_knee", "right_ankle", "right_shoulder", "right_elbow",
    "right_wrist", "left_hip", "left_knee", "left_ankle", "left_shoulder", "left_elbow", "left_wrist",
)
# Each leg's hip, knee and ankle links (indices into LINK_NAMES)
LEG_LINKS: dict[str, tuple[int, int, int]] = {s: (LINK_NAMES.index(f"{s}_hip"), LINK_NAMES.index(f"{s}_knee"),
                                                  LINK_NAMES.index(f"{s}_ankle")) for s in ("left", "right")}
LINK_PARENT: dict[str, str | None] = {
    "root": None, "chest": "root", "neck": "chest", "right_hip": "root", "right_knee": "right_hip",
    "right_ankle": "right_knee", "right_shoulder": "chest", "right_elbow": "right_shoulder",
    "right_wrist": "right_elbow", "left_hip": "root", "left_knee": "left_hip", "left_ankle": "left_knee",
    "left_shoulder": "chest", "left_elbow": "left_shoulder", "left_wrist": "left_elbow",
}
FOOT_LINKS: tuple[str, str] = ("left_ankle", "right_ankle")
SIDES: tuple[str, str] = ("left", "right")
OTHER_SIDE: dict[str, str] = {"left": "right", "right": "left"}

# Segment geometry of the character [m] (joint offsets of the URDF times its 0.25 scaling).
THIGH_LENGTH_M = 1.686184 * URDF_GLOBAL_SCALING
SHANK_LENGTH_M = 1.639480 * URDF_GLOBAL_SCALING
# The foot's box is 0.22 high and centred 0.09 below the ankle joint (model units): its sole is 0.2 below [m].
ANKLE_HEIGHT_M = (0.09 + 0.22 / 2) * URDF_GLOBAL_SCALING  # ankle joint above the sole with the foot flat [m]
HIP_HALF_WIDTH_M = 0.339548 * URDF_GLOBAL_SCALING
FOOT_LENGTH_M = 0.708 * URDF_GLOBAL_SCALING  # Table 2: 0.18
FOOT_WIDTH_M = 0.36 * URDF_GLOBAL_SCALING  # box x-extent 0.177, z-extent 0.09 (model axes)
FOOT_CENTER_AHEAD_OF_ANKLE_M = 0.18 * URDF_GLOBAL_SCALING


def subtree_links(joint: str) -> list[int]:
    """Indices (in LINK_NAMES) of the links moved by ``joint``: its child link and everything below it."""
    out = []
    for i, name in enumerate(LINK_NAMES):
        cur: str | None = name
        while cur is not None and cur != joint:
            cur = LINK_PARENT[cur]
        if cur is not None:
            out.append(i)
    return out


def chain_to_root(link: str) -> list[str]:
    """Joint names from ``link`` up to (not including) the pelvis, child first."""
    chain: list[str] = []
    cur: str | None = link
    while cur is not None and cur != "root":
        if cur in JOINT_BY_NAME:
            chain.append(cur)
        cur = LINK_PARENT[cur]
    return chain


def model_quat_from_canonical(q_canonical_wxyz: np.ndarray) -> np.ndarray:
    """Joint rotation in model axes from the same relative rotation in canonical (world-aligned) axes."""
    return rot.multiply(rot.multiply(rot.conjugate(Q_WORLD_MODEL), q_canonical_wxyz), Q_WORLD_MODEL)


# The two changes of axes are linear maps of the quaternion (the scalar part kept, the vector part rotated):
# 4x4 matrices acting on rows, built from the functions above.
_MODEL_FROM_CANONICAL_T = np.array([model_quat_from_canonical(e) for e in np.eye(4)])
_CANONICAL_FROM_MODEL_T = np.array([rot.multiply(rot.multiply(Q_WORLD_MODEL, e), rot.conjugate(Q_WORLD_MODEL))
                                    for e in np.eye(4)])


def batch_model_quat_from_canonical(q_canonical_wxyz: np.ndarray) -> np.ndarray:
    """:func:`model_quat_from_canonical` of each row, (n, 4)."""
    return q_canonical_wxyz @ _MODEL_FROM_CANONICAL_T


def canonical_quat_from_model(q_model_wxyz: np.ndarray) -> np.ndarray:
    """Joint rotation in canonical (world-aligned) axes from the same rotation in model axes."""
    return np.asarray(q_model_wxyz, dtype=float) @ _CANONICAL_FROM_MODEL_T


# Character links whose frame origin is the joint of the same name on the operator (canonical joints); his "PELVIS"
# is read at his hip joints' midpoint where they are compared (processing/body_parameters.paired_operator_joints).
JOINT_PAIRS: tuple[tuple[str, str], ...] = (
    ("root", "PELVIS"), ("chest", "SPINE_CHEST"), ("neck", "NECK"),
    ("left_hip", "HIP_LEFT"), ("left_knee", "KNEE_LEFT"), ("left_ankle", "ANKLE_LEFT"),
    ("right_hip", "HIP_RIGHT"), ("right_knee", "KNEE_RIGHT"), ("right_ankle", "ANKLE_RIGHT"),
    ("left_shoulder", "SHOULDER_LEFT"), ("left_elbow", "ELBOW_LEFT"), ("left_wrist", "WRIST_LEFT"),
    ("right_shoulder", "SHOULDER_RIGHT"), ("right_elbow", "ELBOW_RIGHT"), ("right_wrist", "WRIST_RIGHT"),
)
CHARACTER_LINKS = np.array([LINK_NAMES.index(c) for c, _ in JOINT_PAIRS])
OPERATOR_JOINTS: tuple[str, ...] = tuple(o for _, o in JOINT_PAIRS)

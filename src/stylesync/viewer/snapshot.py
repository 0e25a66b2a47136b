"""What a viewer draws at one instant, copied out of the control loop so that drawing never touches live state.

A :class:`Snapshot` is made in the loop's thread at a control tick (a few microseconds: small array copies) and
read by the viewer's own thread at its own rate. Everything is in the world frame: z up, metres, wxyz quaternions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from stylesync import rotations as rot
from stylesync.model.character import LINK_NAMES, SHANK_LENGTH_M, THIGH_LENGTH_M
from stylesync.model.state import CharacterState, LinkShape
from stylesync.motion.bounds import ds_com_bound_m, step_length_bound_m
from stylesync.motion.stance_fsm import Stance
from stylesync.processing.joint_map import TRACKED_POSITIONS

FOOT_SOLE_HALF_EXTENTS_M = (0.0885, 0.045)  # half length and half width of the foot box (collision shape) [m]
FOOT_CENTRE_AHEAD_M = 0.045  # the foot box centre lies this far ahead of the ankle joint [m]
OPERATOR_BONES: tuple[tuple[str, str], ...] = (
    ("PELVIS", "HIP_LEFT"), ("HIP_LEFT", "KNEE_LEFT"), ("KNEE_LEFT", "ANKLE_LEFT"), ("ANKLE_LEFT", "FOOT_LEFT"),
    ("PELVIS", "HIP_RIGHT"), ("HIP_RIGHT", "KNEE_RIGHT"), ("KNEE_RIGHT", "ANKLE_RIGHT"),
    ("ANKLE_RIGHT", "FOOT_RIGHT"), ("PELVIS", "SPINE_CHEST"), ("SPINE_CHEST", "NECK"), ("NECK", "HEAD"),
    ("SPINE_CHEST", "SHOULDER_LEFT"), ("SHOULDER_LEFT", "ELBOW_LEFT"), ("ELBOW_LEFT", "WRIST_LEFT"),
    ("SPINE_CHEST", "SHOULDER_RIGHT"), ("SHOULDER_RIGHT", "ELBOW_RIGHT"), ("ELBOW_RIGHT", "WRIST_RIGHT"),
)
_LINK = {n: i for i, n in enumerate(LINK_NAMES)}
_CHAR_LEG_M = THIGH_LENGTH_M + SHANK_LENGTH_M


@dataclass(frozen=True)
class Snapshot:
    time_s: float
    root_pos_world: np.ndarray  # (3,) [m]
    root_quat_wxyz: np.ndarray  # (4,)
    joint_pos: np.ndarray  # (n_joints, 4) as CharacterState.joint_pos
    link_com_world: np.ndarray  # (n_links, 3) [m]
    link_quat_wxyz: np.ndarray  # (n_links, 4) canonical link orientations
    com_world: np.ndarray  # (3,) character COM [m]
    feet_down: dict[str, bool]  # foot on the ground, per side
    ankle_world: dict[str, np.ndarray]  # ankle joint positions [m]
    foot_yaw_rad: dict[str, float]
    character_stance: Stance
    operator_stance: Stance
    operator_pos_world: dict[str, np.ndarray] | None  # operator joints, operator scale [m]
    scale: float  # character leg length / operator leg length (Eq. 9)
    bounds_active: dict[str, bool]  # movement bound exceeded right now (Eq. 24, 26, 28)
    balls_world: tuple[np.ndarray, ...] = ()
    fell: bool = False


def snapshot_from_state(state: CharacterState, com_world: np.ndarray, character_stance: Stance,
                        operator_stance: Stance, operator_pos: dict[str, np.ndarray] | None, scale: float,
                        bounds_active: dict[str, bool], balls_world: tuple[np.ndarray, ...] = (),
                        feet_down: dict[str, bool] | None = None, fell: bool = False) -> Snapshot:
    if feet_down is None:
        feet_down = state.feet_pressing()
    ankles = {s: state.link_origin_world[_LINK[f"{s}_ankle"]].copy() for s in ("left", "right")}
    yaw = {s: rot.yaw_from_quat(state.link_quat_wxyz[_LINK[f"{s}_ankle"]]) for s in ("left", "right")}
    op = None if operator_pos is None else {k: np.array(v, dtype=float) for k, v in operator_pos.items()}
    return Snapshot(state.time_s, state.root_pos_world.copy(), state.root_quat_wxyz.copy(), state.joint_pos.copy(),
                    state.link_com_world.copy(), state.link_quat_wxyz.copy(), np.array(com_world),
                    dict(feet_down), ankles, yaw, character_stance, operator_stance, op, float(scale),
                    dict(bounds_active), tuple(np.array(b) for b in balls_world), fell)


def shape_poses(shapes: list[LinkShape], snap: Snapshot) -> list[tuple[np.ndarray, np.ndarray]]:
    """World (position, wxyz) of each collision shape."""
    out = []
    for sh in shapes:
        q_link = snap.link_quat_wxyz[sh.link]
        out.append((snap.link_com_world[sh.link] + rot.rotate(q_link, sh.pos_link),
                    rot.multiply(q_link, sh.quat_link_wxyz)))
    return out


def sole_corners(ankle_world: np.ndarray, yaw_rad: float) -> np.ndarray:
    """(4, 2) horizontal corners of a flat foot's sole [m]."""
    hx, hy = FOOT_SOLE_HALF_EXTENTS_M
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    R = np.array([[c, -s], [s, c]])
    a = FOOT_CENTRE_AHEAD_M
    local = np.array([[a + hx, hy], [a + hx, -hy], [a - hx, -hy], [a - hx, hy]])
    return ankle_world[:2] + local @ R.T


def support_polygon(snap: Snapshot) -> np.ndarray:
    """(k, 2) convex hull of the soles on the ground, counter-clockwise; empty when no foot is down."""
    pts = [sole_corners(snap.ankle_world[s], snap.foot_yaw_rad[s]) for s in ("left", "right") if snap.feet_down[s]]
    if not pts:
        return np.zeros((0, 2))
    p = np.concatenate(pts)
    try:
        hull = ConvexHull(p)
    except QhullError:
        return p
    return p[hull.vertices]


def bound_circles(snap: Snapshot) -> list[tuple[str, np.ndarray, float]]:
    """Movement bounds drawn on the ground: (kind, centre (2,), radius [m]). Eq. 24 in double stance around the
    support centre; Eq. 28 in single stance around the stance ankle."""
    if snap.character_stance is Stance.DS:
        centre = 0.5 * (snap.ankle_world["left"][:2] + snap.ankle_world["right"][:2])
        return [("ds_com", centre, ds_com_bound_m())]
    stance = "left" if snap.character_stance is Stance.LS else "right"
    op_leg_m = _CHAR_LEG_M / max(snap.scale, 1e-6)
    return [("step_length", snap.ankle_world[stance][:2], step_length_bound_m(_CHAR_LEG_M, op_leg_m))]


def operator_overlay(snap: Snapshot, offset_world: np.ndarray) -> np.ndarray | None:
    """(n_bones, 2, 3) operator bones scaled to the character (Eq. 9 scale) about the operator's pelvis ground
    point, moved to the character's pelvis ground point plus ``offset_world``."""
    op = snap.operator_pos_world
    if op is None or any(n not in op for n in TRACKED_POSITIONS):
        return None
    base = np.array([op["PELVIS"][0], op["PELVIS"][1], 0.0])
    anchor = np.array([snap.link_com_world[0][0], snap.link_com_world[0][1], 0.0]) + offset_world
    return np.array([[anchor + snap.scale * (op[a] - base), anchor + snap.scale * (op[b] - base)]
                     for a, b in OPERATOR_BONES])

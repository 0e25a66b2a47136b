"""Operator body parameters (Sec. 4.2): link lengths (Eq. 1) and the operator COM (Eq. 6).

Without a body point cloud the link masses come from a published anthropometric table: Winter, *Biomechanics and
Motor Control of Human Movement*, 4th ed. (2009), Table 4.1 (segment mass fractions and COM locations, after
Dempster 1955). With a body point cloud, masses come from link volumes by the micro-cuboid method (Eq. 2-5,
``processing/point_cloud_volume.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stylesync.processing.point_cloud_volume import link_volumes, masses_by_volume
from stylesync.rotations import yaw_from_quat

# (segment, proximal joint, distal joint, mass fraction, COM fraction from the proximal end), Winter Table 4.1.
# The trunk (0.497) runs from the pelvis to the neck; the forearm includes the hand (0.016 + 0.006).
WINTER_SEGMENTS: tuple[tuple[str, str, str, float, float], ...] = (
    ("trunk", "PELVIS", "NECK", 0.497, 0.50),
    ("head_neck", "NECK", "HEAD", 0.081, 1.0),
    ("thigh_left", "HIP_LEFT", "KNEE_LEFT", 0.100, 0.433),
    ("thigh_right", "HIP_RIGHT", "KNEE_RIGHT", 0.100, 0.433),
    ("shank_left", "KNEE_LEFT", "ANKLE_LEFT", 0.0465, 0.433),
    ("shank_right", "KNEE_RIGHT", "ANKLE_RIGHT", 0.0465, 0.433),
    ("foot_left", "ANKLE_LEFT", "FOOT_LEFT", 0.0145, 0.50),
    ("foot_right", "ANKLE_RIGHT", "FOOT_RIGHT", 0.0145, 0.50),
    ("upper_arm_left", "SHOULDER_LEFT", "ELBOW_LEFT", 0.028, 0.436),
    ("upper_arm_right", "SHOULDER_RIGHT", "ELBOW_RIGHT", 0.028, 0.436),
    ("forearm_hand_left", "ELBOW_LEFT", "WRIST_LEFT", 0.022, 0.682),
    ("forearm_hand_right", "ELBOW_RIGHT", "WRIST_RIGHT", 0.022, 0.682),
)
WINTER_TOTAL_FRACTION = sum(s[3] for s in WINTER_SEGMENTS)  # 1.0 within rounding
STATURE_PER_LEG_LENGTH = 1.0 / 0.530  # Winter Fig. 4.1: hip joint at 0.530 H


def link_length(p_proximal: np.ndarray, p_distal: np.ndarray) -> float:
    """Eq. 1: L_i = |p_i - p_{i-1}| [m]."""
    return math.dist(np.asarray(p_distal, dtype=float).tolist(), np.asarray(p_proximal, dtype=float).tolist())


def segment_mass_fractions() -> dict[str, float]:
    return {s[0]: s[3] / WINTER_TOTAL_FRACTION for s in WINTER_SEGMENTS}


def com_from_joints(pos: dict[str, np.ndarray], fractions: dict[str, float] | None = None) -> np.ndarray:
    """Eq. 6: p_COM = Σ vp_i p_i^L, with link COMs placed along each segment (Winter) [m]."""
    fractions = fractions or segment_mass_fractions()
    com = np.zeros(3)
    for name, prox, dist, _, along in WINTER_SEGMENTS:
        p_link = pos[prox] + along * (pos[dist] - pos[prox])
        com += fractions[name] * p_link
    return com / sum(fractions.values())


def hip_centre_world(pos: dict[str, np.ndarray]) -> np.ndarray:
    """(3,) the midpoint of the operator's two hip joints [m], world frame: where the character's root is on its own
    body (its hip joints lie level with its root), whatever his skeleton calls its pelvis (CMU's ``Hips`` root sits
    about 0.1 m above the hip joints, the CMU-dev ``hip`` 0.03 m below, DeepMimic's and the Kinect's pelvis level with
    them)."""
    return 0.5 * (np.asarray(pos["HIP_LEFT"], dtype=float) + np.asarray(pos["HIP_RIGHT"], dtype=float))


def paired_operator_joints(pos: dict[str, np.ndarray], names: tuple[str, ...]) -> np.ndarray:
    """(len(names), 3) his joints ``names`` [m], world frame, with his pelvis (``"PELVIS"``) read at his hip joints'
    midpoint (:func:`hip_centre_world`): the points of his body that the character's links of the same place are
    compared with (the imitation metrics). The character's root is level with its hip joints, and a skeleton puts
    its pelvis joint anywhere from 0.03 m below them (CMU-dev) to 0.1 m above (CMU's ``Hips``)."""
    return np.array([hip_centre_world(pos) if n == "PELVIS" else pos[n] for n in names])


def operator_pelvis_world(pos: dict[str, np.ndarray], from_hip_joints: bool) -> np.ndarray:
    """(3,) his pelvis as the retargeting of Eq. 9-10 takes it [m]: :func:`hip_centre_world` with
    ``from_hip_joints`` (MotionConfig.pelvis_from_hip_joints), else his skeleton's pelvis joint."""
    return hip_centre_world(pos) if from_hip_joints else pos["PELVIS"]


def leg_length_m(pos: dict[str, np.ndarray], ankle_height_m: float) -> float:
    """Hip-joint height of a straight leg: thigh + shank (Eq. 1) + ankle height [m], mean of both legs."""
    lengths = [link_length(pos[f"HIP_{s}"], pos[f"KNEE_{s}"]) + link_length(pos[f"KNEE_{s}"], pos[f"ANKLE_{s}"])
               for s in ("LEFT", "RIGHT")]
    return 0.5 * (lengths[0] + lengths[1]) + ankle_height_m


# Table 2 rows: (row, proximal joint, distal joint, Winter mass fraction of one such link). Winter splits the trunk
# 0.497 into thorax 0.216 + abdomen 0.139 (our torso, 0.355) and pelvis 0.142.
TABLE2_ROWS: tuple[tuple[str, str, str, float], ...] = (
    ("pelvis", "PELVIS", "SPINE_CHEST", 0.142),
    ("torso", "SPINE_CHEST", "NECK", 0.355),
    ("head", "NECK", "HEAD", 0.081),
    ("upper_arm", "SHOULDER_{S}", "ELBOW_{S}", 0.028),
    ("lower_arm", "ELBOW_{S}", "WRIST_{S}", 0.022),
    ("upper_leg", "HIP_{S}", "KNEE_{S}", 0.100),
    ("lower_leg", "KNEE_{S}", "ANKLE_{S}", 0.0465),
    ("foot", "ANKLE_{S}", "FOOT_{S}", 0.0145),
)


@dataclass
class LinkTable:
    """The operator's links as in Table 2's human column: length [m] (Eq. 1) and mass [kg] (Eq. 2)."""

    total_mass_kg: float
    length_m: dict[str, float]
    mass_kg: dict[str, float]
    method: str  # "point cloud (Eq. 2-5)" or "anthropometric table (Winter 2009)"
    com_world: np.ndarray  # operator COM of the first frame (Eq. 6) [m]

    def as_text(self) -> str:
        lines = [f"operator links ({self.method}), total mass {self.total_mass_kg:.1f} kg",
                 f"{'link':<10} {'length [m]':>10} {'mass [kg]':>10} {'mass [%]':>9}"]
        for name in self.length_m:
            m = self.mass_kg[name]
            lines.append(f"{name:<10} {self.length_m[name]:>10.3f} {m:>10.2f} {100 * m / self.total_mass_kg:>9.1f}")
        lines.append("COM (first frame) [m]: " + " ".join(f"{v:.3f}" for v in self.com_world))
        return "\n".join(lines)


def _link_ends(row: tuple[str, str, str, float], side: str) -> tuple[str, str]:
    return row[1].format(S=side), row[2].format(S=side)


def measure_operator(frames: list, total_mass_kg: float, point_cloud_world: np.ndarray | None = None) -> LinkTable:
    """Sec. 4.2 on operator frames: link lengths by Eq. 1 (median over the frames, mean of both sides), masses by
    volume proportion from a point cloud (Eq. 2-5) or from Winter's table, the COM by Eq. 6."""
    if not (np.isfinite(total_mass_kg) and total_mass_kg > 0):
        raise ValueError(f"total mass must be > 0 kg, got {total_mass_kg}")
    length: dict[str, float] = {}
    for row in TABLE2_ROWS:
        sides = ("LEFT", "RIGHT") if "{S}" in row[1] else ("",)
        vals = [link_length(f.pos(a), f.pos(b)) for f in frames for a, b in (_link_ends(row, s) for s in sides)]
        length[row[0]] = float(np.median(vals))
    first = frames[0]
    pos = {n: first.pos(n) for n in first_joint_names()}
    if point_cloud_world is None:
        fractions = {row[0]: row[3] for row in TABLE2_ROWS}
        total = sum(f * (2 if "{S}" in r[1] else 1) for r, f in zip(TABLE2_ROWS, fractions.values(), strict=True))
        mass = {n: total_mass_kg * f / total for n, f in fractions.items()}
        method = "anthropometric table (Winter 2009)"
    else:
        links = {}
        for row in TABLE2_ROWS:
            for s in (("LEFT", "RIGHT") if "{S}" in row[1] else ("",)):
                a, b = _link_ends(row, s)
                links[f"{row[0]}{'_' + s.lower() if s else ''}"] = (pos[a], pos[b])
        vols = link_volumes(point_cloud_world, links, yaw_from_quat(first.quat("PELVIS")))
        by_link = masses_by_volume(vols, total_mass_kg)
        mass = {row[0]: (0.5 * (by_link[f"{row[0]}_left"] + by_link[f"{row[0]}_right"]) if "{S}" in row[1]
                         else by_link[row[0]]) for row in TABLE2_ROWS}
        method = "point cloud (Eq. 2-5)"
    return LinkTable(total_mass_kg, length, mass, method, com_from_joints(pos))


def first_joint_names() -> tuple[str, ...]:
    """Joints Eq. 6 and the link table read."""
    names = {n for seg in WINTER_SEGMENTS for n in seg[1:3]}
    for row in TABLE2_ROWS:
        for s in ("LEFT", "RIGHT"):
            names |= set(_link_ends(row, s))
    return tuple(sorted(names))

"""Operator body parameters (Sec. 4.2): link lengths (Eq. 1) and the operator COM (Eq. 6).

Without a body point cloud the link masses come from a published anthropometric table: Winter, *Biomechanics and
Motor Control of Human Movement*, 4th ed. (2009), Table 4.1 (segment mass fractions and COM locations, after
Dempster 1955). The micro-cuboid volume method (Eq. 2-5) needs a point cloud and lives in
``processing/point_cloud_volume.py`` when one is available.
"""

from __future__ import annotations

import numpy as np

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
    return float(np.linalg.norm(np.asarray(p_distal) - np.asarray(p_proximal)))


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


def leg_length_m(pos: dict[str, np.ndarray], ankle_height_m: float) -> float:
    """Hip-joint height of a straight leg: thigh + shank (Eq. 1) + ankle height [m], mean of both legs."""
    lengths = [link_length(pos[f"HIP_{s}"], pos[f"KNEE_{s}"]) + link_length(pos[f"KNEE_{s}"], pos[f"ANKLE_{s}"])
               for s in ("LEFT", "RIGHT")]
    return float(np.mean(lengths)) + ankle_height_m

"""Two-link leg inverse kinematics in a given plane (Sec. 5.3, after Kavafoglu et al. [8]).

Specifying the leg's motion plane by its normal N turns the 3D IK of hip and knee into a 2D problem with one
solution (knee bent forward). Segment frames are canonical: columns (forward, left, up) with "up" pointing
from the distal to the proximal joint and "left" along N; the knee hinge turns about -left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot

# Near full extension the knee angle is ill-conditioned (d(reach)/d(angle) -> 0: 1 cm of pelvis noise would swing
# the knee by 0.25 rad). Reaches beyond SOFT_REACH_START of the leg length are compressed smoothly towards
# MAX_REACH (knee about 0.2 rad), which keeps the reference smooth and the knee off its lock.
SOFT_REACH_START = 0.97
MAX_REACH = 0.995


def soft_reach(dist_m: float, leg_m: float) -> float:
    """Hip-ankle distance actually reached [m]: identity up to SOFT_REACH_START·leg, then tanh-compressed."""
    d0, d1 = SOFT_REACH_START * leg_m, MAX_REACH * leg_m
    if dist_m <= d0:
        return dist_m
    return d0 + (d1 - d0) * float(np.tanh((dist_m - d0) / (d1 - d0)))


@dataclass(frozen=True)
class LegIkSolution:
    thigh_quat_wxyz: np.ndarray  # canonical world orientation of the thigh
    shank_quat_wxyz: np.ndarray
    knee_angle_rad: float  # hinge angle about -left (negative = flexed, as in the URDF limits)
    knee_world: np.ndarray
    ankle_world: np.ndarray  # reached ankle position (the target, moved within reach) [m]


def _frame(up: np.ndarray, left: np.ndarray) -> np.ndarray:
    left = left - np.dot(left, up) * up
    left /= np.linalg.norm(left)
    return np.column_stack([rot.cross(left, up), left, up])


def solve_leg(hip: np.ndarray, ankle_target: np.ndarray, thigh_m: float, shank_m: float,
              plane_normal: np.ndarray) -> LegIkSolution:
    hip = np.asarray(hip, dtype=float)
    d = np.asarray(ankle_target, dtype=float) - hip
    dist = float(np.linalg.norm(d))
    lo = abs(thigh_m - shank_m) + 1e-4
    u = d / dist if dist > 1e-9 else np.array([0.0, 0.0, -1.0])
    dist = max(soft_reach(dist, thigh_m + shank_m), lo)
    n = np.asarray(plane_normal, dtype=float)
    n = n - np.dot(n, u) * u
    if np.linalg.norm(n) < 1e-6:
        n = rot.cross(u, np.array([1.0, 0.0, 0.0]))
    n /= np.linalg.norm(n)
    v = rot.cross(u, n)  # in-plane, forward of the hip-ankle line
    cos_a = (thigh_m**2 + dist**2 - shank_m**2) / (2 * thigh_m * dist)
    alpha = float(np.arccos(np.clip(cos_a, -1.0, 1.0)))
    knee = hip + thigh_m * (np.cos(alpha) * u + np.sin(alpha) * v)
    ankle = hip + dist * u
    R_thigh = _frame((hip - knee) / thigh_m, n)
    R_shank = _frame((knee - ankle) / shank_m, n)
    q_thigh, q_shank = rot.quat_from_matrix(R_thigh), rot.quat_from_matrix(R_shank)
    q_rel = rot.multiply(rot.conjugate(q_thigh), q_shank)
    knee_angle = rot.twist_angle(q_rel, np.array([0.0, -1.0, 0.0]))
    return LegIkSolution(q_thigh, q_shank, knee_angle, knee, ankle)

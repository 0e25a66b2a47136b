"""Two-link leg inverse kinematics in a given plane (Sec. 5.3, after Kavafoglu et al. [8]).

Specifying the leg's motion plane by its normal N turns the 3D IK of hip and knee into a 2D problem with one
solution (knee bent forward). Segment frames are canonical: columns (forward, left, up) with "up" pointing
from the distal to the proximal joint and "left" along N; the knee hinge turns about -left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot

# Near full extension the knee angle is ill-conditioned (d(reach)/d(angle) -> 0: 1 cm of pelvis noise would swing
# the knee by 0.25 rad). Reaches beyond SOFT_REACH_START of the leg length are compressed smoothly towards
# MAX_REACH (knee about 0.2 rad), which keeps the reference smooth and the knee off its lock.
SOFT_REACH_START = 0.97
MAX_REACH = 0.995
_MINUS_LEFT = np.array([0.0, -1.0, 0.0])  # the knee hinge's axis in the thigh's canonical frame


def soft_reach(dist_m: float, leg_m: float) -> float:
    """Hip-ankle distance actually reached [m]: identity up to SOFT_REACH_START·leg, then tanh-compressed."""
    d0, d1 = SOFT_REACH_START * leg_m, MAX_REACH * leg_m
    if dist_m <= d0:
        return dist_m
    return d0 + (d1 - d0) * math.tanh((dist_m - d0) / (d1 - d0))


@dataclass(frozen=True)
class LegIkSolution:
    thigh_quat_wxyz: np.ndarray  # canonical world orientation of the thigh
    shank_quat_wxyz: np.ndarray
    knee_angle_rad: float  # hinge angle about -left (negative = flexed, as in the URDF limits)
    knee_world: np.ndarray
    ankle_world: np.ndarray  # reached ankle position (the target, moved within reach) [m]


def _quat_of_frame(up: tuple[float, float, float], left: tuple[float, float, float]) -> np.ndarray:
    """Canonical segment orientation (w, x, y, z) of the frame whose columns are (left × up, left, up), ``left``
    first made orthogonal to the unit ``up`` and normalised. Python floats: this runs four times per control tick."""
    ux, uy, uz = up
    lx, ly, lz = left
    d = lx * ux + ly * uy + lz * uz
    lx, ly, lz = lx - d * ux, ly - d * uy, lz - d * uz
    n = math.sqrt(lx * lx + ly * ly + lz * lz)
    lx, ly, lz = lx / n, ly / n, lz / n
    fx, fy, fz = ly * uz - lz * uy, lz * ux - lx * uz, lx * uy - ly * ux
    return rot.quat_from_matrix_rows((fx, lx, ux), (fy, ly, uy), (fz, lz, uz))


def solve_leg(hip: np.ndarray, ankle_target: np.ndarray, thigh_m: float, shank_m: float,
              plane_normal: np.ndarray) -> LegIkSolution:
    hx, hy, hz = np.asarray(hip, dtype=float).tolist()
    tx, ty, tz = np.asarray(ankle_target, dtype=float).tolist()
    dx, dy, dz = tx - hx, ty - hy, tz - hz
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    lo = abs(thigh_m - shank_m) + 1e-4
    ux, uy, uz = (dx / dist, dy / dist, dz / dist) if dist > 1e-9 else (0.0, 0.0, -1.0)
    dist = max(soft_reach(dist, thigh_m + shank_m), lo)
    nx, ny, nz = np.asarray(plane_normal, dtype=float).tolist()
    d = nx * ux + ny * uy + nz * uz
    nx, ny, nz = nx - d * ux, ny - d * uy, nz - d * uz
    n = math.sqrt(nx * nx + ny * ny + nz * nz)
    if n < 1e-6:  # the plane's normal along the hip-ankle line: any plane through it, u × x̂
        nx, ny, nz = 0.0, uz, -uy
        n = math.sqrt(ny * ny + nz * nz)
    nx, ny, nz = nx / n, ny / n, nz / n
    vx, vy, vz = uy * nz - uz * ny, uz * nx - ux * nz, ux * ny - uy * nx  # in-plane, forward of the hip-ankle line
    cos_a = (thigh_m**2 + dist**2 - shank_m**2) / (2 * thigh_m * dist)
    alpha = math.acos(min(max(cos_a, -1.0), 1.0))
    ca, sa = math.cos(alpha), math.sin(alpha)
    kx, ky, kz = (hx + thigh_m * (ca * ux + sa * vx), hy + thigh_m * (ca * uy + sa * vy),
                  hz + thigh_m * (ca * uz + sa * vz))
    ax, ay, az = hx + dist * ux, hy + dist * uy, hz + dist * uz
    normal = (nx, ny, nz)
    q_thigh = _quat_of_frame(((hx - kx) / thigh_m, (hy - ky) / thigh_m, (hz - kz) / thigh_m), normal)
    q_shank = _quat_of_frame(((kx - ax) / shank_m, (ky - ay) / shank_m, (kz - az) / shank_m), normal)
    q_rel = rot.multiply(rot.conjugate(q_thigh), q_shank)
    knee_angle = rot.twist_angle(q_rel, _MINUS_LEFT)
    return LegIkSolution(q_thigh, q_shank, knee_angle, np.array([kx, ky, kz]), np.array([ax, ay, az]))

"""Ground reaction forces that realise a desired rate of change of the body's momentum (Sec. 6.2-6.3).

The COM virtual force of Eq. 16 and the root virtual torque of Eq. 16/18 are, taken together, a desired wrench on
the whole body about its COM: ``F_d = m (p̈_d + g ẑ)`` and ``τ_d``. Only the ground can give it, through the soles
in contact: each sole corner passes a force inside its friction cone (linearised as a 4-sided pyramid), which
keeps every centre of pressure on its sole and every foot from sliding or twisting (the constraints that
support.py and bounds.py approximate one at a time). This module gives the pyramid's edges at every sole corner
and the wrench about the COM each edge's unit force makes, ``A = [β_e ; (p_c - c) × β_e]``; the magnitudes λ >= 0
are found together with the body's accelerations (inverse_dynamics.py), with the weight ε_s on a foot's λ growing
as its stance weight falls, so that a foot about to lift off is unloaded before it leaves the ground.
"""

from __future__ import annotations

import functools

import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import ANKLE_HEIGHT_M, FOOT_CENTER_AHEAD_OF_ANKLE_M, FOOT_LENGTH_M, FOOT_WIDTH_M

SOLE_MARGIN = 0.9  # fraction of the sole's length and width the corner forces may use
FRICTION_MARGIN = 0.8  # fraction of the friction coefficient the pyramid uses
COP_MARGIN = 0.9  # fraction of the support's extent the desired horizontal force may use
MOMENTUM_ACCEL_ALLOWANCE_MPS2 = 0.5  # horizontal COM acceleration allowed beyond the pendulum's [m/s²]
REGULARISATION = 1e-4  # ε of a full-weight foot [1/N² against N² of residual]
MIN_WEIGHT = 0.05  # a stance weight below this is treated as this (ε_s = REGULARISATION / weight)
_HALF_L, _HALF_W = SOLE_MARGIN * FOOT_LENGTH_M / 2, SOLE_MARGIN * FOOT_WIDTH_M / 2
# Sole corners relative to the ankle joint in the foot's canonical frame (x forward, y left, z up) [m], (4, 3).
SOLE_CORNERS_IN_FOOT = np.array([[FOOT_CENTER_AHEAD_OF_ANKLE_M + sx * _HALF_L, sy * _HALF_W, -ANKLE_HEIGHT_M]
                                 for sx in (1.0, -1.0) for sy in (1.0, -1.0)])
_EDGE_DIRS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


def sole_corners_world(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray) -> np.ndarray:
    """(4, 3) world positions of a foot's sole corners [m]."""
    return np.asarray(ankle_world, dtype=float) + SOLE_CORNERS_IN_FOOT @ rot.matrix_from_quat(foot_quat_wxyz).T


def sole_touches(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray, pressing: bool, gap_m: float) -> bool:
    """Whether a foot can be given ground forces: it presses the ground (``CharacterState.feet_pressing``), or the
    lowest corner of its sole is within ``gap_m`` of the ground (``gap_m`` > 0). The second case is a planted foot that
    has just been unloaded: left out of the plan for as long as it does not press, it is no longer held where it
    is, and the plan switches between one and two supporting feet from one tick to the next as the load shifts."""
    return pressing or (gap_m > 0 and float(sole_corners_world(ankle_world, foot_quat_wxyz)[:, 2].min()) < gap_m)


@functools.lru_cache(maxsize=8)
def _pyramid(friction: float) -> tuple[np.ndarray, np.ndarray]:
    """The pyramid's unit edges (4, 3) and the rows (12, 3) of the map l -> (l × β_e)_e for a lever arm l."""
    mu = FRICTION_MARGIN * friction
    e = np.column_stack([mu * _EDGE_DIRS, np.ones(4)])
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    # l × β = Σ_i l_i (e_i × β): columns e_i × β, edge by edge
    moment_rows = np.concatenate([np.cross(np.eye(3), b).T for b in e])
    e.setflags(write=False)
    moment_rows.setflags(write=False)
    return e, moment_rows


@functools.lru_cache(maxsize=8)
def _tiled_edges(friction: float, n_corners: int) -> np.ndarray:
    """(3, 4 n_corners): the pyramid's edges as columns, corner by corner."""
    out = np.tile(_pyramid(friction)[0].T, n_corners)
    out.setflags(write=False)
    return out


def pyramid_edges(friction: float) -> np.ndarray:
    """(4, 3) unit edges of the linearised friction cone of a flat ground."""
    return _pyramid(friction)[0]


def wrench_basis(com_world: np.ndarray, corners_world: dict[str, np.ndarray],
                 friction: float) -> tuple[np.ndarray, np.ndarray]:
    """The pyramid's unit edges (4, 3), the same at every corner, and the wrench about the COM of each edge's unit
    force, A (6, n_λ): n_λ = 16 per foot, feet in ``corners_world`` order, corner by corner, edge by edge."""
    edges, moment_rows = _pyramid(friction)
    levers = np.concatenate(list(corners_world.values())) - com_world  # (n_corners, 3)
    n = 4 * len(levers)
    out = np.empty((6, n))
    out[:3] = _tiled_edges(friction, len(levers))
    out[3:] = (levers @ moment_rows.T).reshape(n, 3).T
    return edges, out


def feasible_horizontal_force(force_n: np.ndarray, com_world: np.ndarray, corners_world: dict[str, np.ndarray],
                              mass_kg: float, gravity_mps2: float) -> np.ndarray:
    """The desired force (3,) [N] with its horizontal part limited to what a centre of pressure inside the support
    can give: by the linear inverted pendulum (the model of Eq. 21), m p̈ = m g / h (c - p_cop) per horizontal
    axis, with p_cop within the soles' extent on that axis, shrunk by COP_MARGIN about its middle. A larger
    request cannot be met by the ground; left in the desired wrench, it would be traded against the vertical force
    (more weight for more friction) and the moment, which lifts or tips the body."""
    out = np.array(force_n, dtype=float)
    if not corners_world:
        return out
    pts = np.concatenate(list(corners_world.values()))
    h = max(float(com_world[2]) - float(pts[:, 2].sum()) / len(pts), 0.1)
    k = mass_kg * gravity_mps2 / h
    lo, hi = pts[:, :2].min(axis=0).tolist(), pts[:, :2].max(axis=0).tolist()
    # The range always holds zero (with the COM beyond the margin the pendulum model would ask for a push
    # outwards), and is widened by MOMENTUM_ACCEL_ALLOWANCE_MPS2: a change of the body's angular momentum (the
    # hip strategy of a squat's leaning trunk) gives some horizontal force the pendulum does not.
    extra = mass_kg * MOMENTUM_ACCEL_ALLOWANCE_MPS2
    for ax in (0, 1):  # Python floats: two scalars per axis
        mid, half = 0.5 * (lo[ax] + hi[ax]), 0.5 * COP_MARGIN * (hi[ax] - lo[ax])
        c = float(com_world[ax])
        lo_f = min(k * (c - mid - half), 0.0) - extra
        hi_f = max(k * (c - mid + half), 0.0) + extra
        out[ax] = min(max(float(out[ax]), lo_f), hi_f)
    return out


def regularisation(corners_world: dict[str, np.ndarray], stance_weight: dict[str, float]) -> np.ndarray:
    """ε per λ (see the module): larger on a foot with a small stance weight."""
    return np.array([REGULARISATION / max(stance_weight.get(s, 0.0), MIN_WEIGHT) for s in corners_world]).repeat(16)

"""Where the feet can push: the support point under each stance foot and the sole's limits (Sec. 6.1-6.3).

A foot flat on the ground passes a vertical force F and a moment to the ground only while its centre of pressure
stays on the sole (the zero-moment-point condition). Ankle torques beyond that roll the foot on an edge instead of
moving the body, so every ankle moment the controller asks of a stance foot is limited here.
"""

from __future__ import annotations

import numpy as np

from stylesync.model.character import FOOT_CENTER_AHEAD_OF_ANKLE_M, FOOT_LENGTH_M, FOOT_WIDTH_M

SOLE_MARGIN = 0.8  # fraction of the sole's length and width a centre of pressure may use
# Effective arm of the friction torque a flat sole resists twisting with (about a third of its half-diagonal) [m].
YAW_FRICTION_ARM_M = 0.03


def clamp_to_foot(point_world: np.ndarray, ankle_world: np.ndarray, foot_yaw_rad: float) -> np.ndarray:
    """The point moved (horizontally) into the sole's rectangle, shrunk by SOLE_MARGIN [m]."""
    c, s = np.cos(foot_yaw_rad), np.sin(foot_yaw_rad)
    d = np.asarray(point_world, dtype=float) - ankle_world
    fwd, left = c * d[0] + s * d[1], -s * d[0] + c * d[1]
    half_l, half_w = SOLE_MARGIN * FOOT_LENGTH_M / 2, SOLE_MARGIN * FOOT_WIDTH_M / 2
    fwd = min(max(fwd, FOOT_CENTER_AHEAD_OF_ANKLE_M - half_l), FOOT_CENTER_AHEAD_OF_ANKLE_M + half_l)
    left = min(max(left, -half_w), half_w)
    return ankle_world + np.array([c * fwd - s * left, s * fwd + c * left, d[2]])


def support_point(com_world: np.ndarray, ankle_world: dict[str, np.ndarray],
                  stance_weight: dict[str, float],
                  foot_yaw_rad: dict[str, float] | None = None) -> dict[str, np.ndarray]:
    """Centre of pressure assumed under each stance foot [m]: its ankle shifted by the COM's horizontal offset
    from the weighted ankles, so that the feet's vertical reactions (w_s m g each) balance the COM exactly. In
    single stance that is the point under the COM; in double stance each reaction stays under its own foot, so
    the legs do not squeeze each other sideways."""
    stance = {s: w for s, w in stance_weight.items() if w > 0}
    if not stance:
        return {}
    weighted = sum(w * ankle_world[s] for s, w in stance.items()) / sum(stance.values())
    delta = np.asarray(com_world, dtype=float) - weighted
    delta[2] = 0.0
    out = {s: ankle_world[s] + delta for s in stance}
    if foot_yaw_rad is not None:  # a centre of pressure cannot leave the sole
        out = {s: clamp_to_foot(p, ankle_world[s], foot_yaw_rad[s]) for s, p in out.items()}
    return out


def limit_ankle_moment(moment_world: np.ndarray, ankle_world: np.ndarray, foot_yaw_rad: float,
                       normal_force_n: float, friction: float) -> np.ndarray:
    """The ankle's world moment [N·m] limited to what a foot carrying ``normal_force_n`` can pass to the ground.

    The joint moment m on the foot is balanced by the ground reaction F ẑ at the centre of pressure p:
    m = -(p - a) × F ẑ, i.e. p - a = (m_y, -m_x) / F. p is clamped to the sole and m recomputed; the
    vertical (twisting) component is limited by the sole's friction, |m_z| <= μ F r (YAW_FRICTION_ARM_M).
    """
    m = np.asarray(moment_world, dtype=float)
    if normal_force_n <= 0:
        return np.zeros(3)
    p = ankle_world + np.array([m[1], -m[0], 0.0]) / normal_force_n
    d = clamp_to_foot(p, ankle_world, foot_yaw_rad) - ankle_world
    yaw_max = friction * normal_force_n * YAW_FRICTION_ARM_M
    return np.array([-d[1] * normal_force_n, d[0] * normal_force_n, min(max(m[2], -yaw_max), yaw_max)])

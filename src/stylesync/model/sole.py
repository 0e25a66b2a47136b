"""The soles of the character's feet: corners in the foot frame and in the world, and the support polygon they
span on the ground."""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import ANKLE_HEIGHT_M, FOOT_CENTER_AHEAD_OF_ANKLE_M, FOOT_LENGTH_M, FOOT_WIDTH_M


def sole_corners_in_foot(share: float = 1.0) -> np.ndarray:
    """(4, 3) corners of the sole relative to the ankle joint in the foot's canonical frame (x forward, y left,
    z up) [m], the sole's length and width scaled by ``share`` about its centre. Order: front-left, front-right,
    back-left, back-right."""
    half_l, half_w = share * FOOT_LENGTH_M / 2, share * FOOT_WIDTH_M / 2
    corners = np.array([[sx * half_l, sy * half_w, 0.0] for sx in (1.0, -1.0) for sy in (1.0, -1.0)])
    return corners + np.array([FOOT_CENTER_AHEAD_OF_ANKLE_M, 0.0, -ANKLE_HEIGHT_M])


_FULL_SOLE_IN_FOOT = sole_corners_in_foot()


def sole_corners_world(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray,
                       corners_in_foot: np.ndarray = _FULL_SOLE_IN_FOOT) -> np.ndarray:
    """(4, 3) world positions of a foot's sole corners [m] (the whole sole unless ``corners_in_foot`` is given)."""
    return np.asarray(ankle_world, dtype=float) + corners_in_foot @ rot.matrix_from_quat(foot_quat_wxyz).T


def sole_within_m(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray, gap_m: float,
                  corners_in_foot: np.ndarray = _FULL_SOLE_IN_FOOT) -> bool:
    """Whether the lowest corner of a foot's sole (the whole sole unless ``corners_in_foot`` is given) is within
    ``gap_m`` of the (level) ground."""
    return float(sole_corners_world(ankle_world, foot_quat_wxyz, corners_in_foot)[:, 2].min()) < gap_m


Point = tuple[float, float]


def convex_hull_points(points: list[Point]) -> list[Point]:
    """Counter-clockwise convex hull of horizontal points given as plain floats (Andrew's monotone chain)."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def half(seq):
        out: list[Point] = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0.0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(reversed(pts))
    return lower[:-1] + upper[:-1]


def convex_hull_xy(points_xy: np.ndarray) -> np.ndarray:
    """(k, 2) counter-clockwise convex hull of horizontal points (n, 2) (:func:`convex_hull_points`)."""
    return np.array(convex_hull_points([(float(x), float(y)) for x, y in np.asarray(points_xy, dtype=float)[:, :2]]))


def outside_distance_m(point_xy: np.ndarray, hull_xy: np.ndarray) -> tuple[float, np.ndarray]:
    """Signed distance of a horizontal point from a convex polygon (counter-clockwise, :func:`convex_hull_xy`):
    > 0 outside, < 0 inside [m]; and the polygon's point nearest to it (the point itself when inside)."""
    p = np.asarray(point_xy, dtype=float)[:2]
    n = len(hull_xy)
    best, nearest, inside_margin = np.inf, p.copy(), np.inf
    inside = n >= 3
    for k in range(n):
        a, b = hull_xy[k], hull_xy[(k + 1) % n]
        ab = b - a
        length2 = float(ab @ ab)
        t = 0.0 if length2 < 1e-12 else min(max(float((p - a) @ ab) / length2, 0.0), 1.0)
        q = a + t * ab
        d = float(np.linalg.norm(p - q))
        if d < best:
            best, nearest = d, q
        if n >= 3:
            cross = ab[0] * (p[1] - a[1]) - ab[1] * (p[0] - a[0])  # > 0: left of the edge (inside)
            if cross < 0.0:
                inside = False
            elif length2 > 1e-12:
                inside_margin = min(inside_margin, cross / np.sqrt(length2))
    if inside:
        return -float(inside_margin), p.copy()
    return best, nearest


def sole_outside_m(point_xy: np.ndarray, ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray) -> float:
    """Signed distance of a horizontal point from one foot's sole: > 0 outside, < 0 inside [m]."""
    return outside_distance_m(point_xy, convex_hull_xy(sole_corners_world(ankle_world, foot_quat_wxyz)[:, :2]))[0]

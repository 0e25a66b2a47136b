"""The soles of the character's feet: corners in the foot frame and in the world, and the support polygon they
span on the ground."""

from __future__ import annotations

import math

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
Corner = tuple[float, float, float]


def sole_corner_points(share: float = 1.0) -> list[Corner]:
    """:func:`sole_corners_in_foot` as plain floats, for the per-tick polygon tests [m]."""
    return [(float(x), float(y), float(z)) for x, y, z in sole_corners_in_foot(share)]


def sole_points_xy(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray, corners: list[Corner]) -> list[Point]:
    """World horizontal positions [m] of a foot's sole corners ``corners`` (:func:`sole_corner_points`):
    :func:`sole_corners_world` on plain floats."""
    w, x, y, z = (float(v) for v in foot_quat_wxyz)
    r00, r01, r02 = 1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)
    r10, r11, r12 = 2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)
    ax, ay = float(ankle_world[0]), float(ankle_world[1])
    return [(ax + r00 * cx + r01 * cy + r02 * cz, ay + r10 * cx + r11 * cy + r12 * cz) for cx, cy, cz in corners]


def sole_points_xy_yaw(ankle_world: np.ndarray, yaw_rad: float, corners: list[Corner]) -> list[Point]:
    """As :func:`sole_points_xy` for a flat foot turned by ``yaw_rad`` about the vertical."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    ax, ay = float(ankle_world[0]), float(ankle_world[1])
    return [(ax + c * cx - s * cy, ay + s * cx + c * cy) for cx, cy, _ in corners]


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
    > 0 outside, < 0 inside [m]; and the polygon's point nearest to it (the point itself when inside)
    (:func:`outside_distance_points`)."""
    polygon = [(float(x), float(y)) for x, y in np.asarray(hull_xy, dtype=float).reshape(-1, 2)]
    distance, nearest = outside_distance_points((float(point_xy[0]), float(point_xy[1])), polygon)
    return distance, np.array(nearest)


def outside_distance_points(point: Point, polygon: list[Point]) -> tuple[float, Point]:
    """:func:`outside_distance_m` on plain floats (a polygon from :func:`convex_hull_points`): the signed distance
    [m], > 0 outside, and the polygon's point nearest to the point (the point itself when inside)."""
    px, py = point
    n = len(polygon)
    best, nearest, margin = math.inf, point, math.inf
    inside = n >= 3
    for k in range(n):
        ax, ay = polygon[k]
        bx, by = polygon[(k + 1) % n]
        ex, ey = bx - ax, by - ay
        length2 = ex * ex + ey * ey
        t = 0.0 if length2 < 1e-12 else min(max(((px - ax) * ex + (py - ay) * ey) / length2, 0.0), 1.0)
        qx, qy = ax + t * ex, ay + t * ey
        d = math.hypot(px - qx, py - qy)
        if d < best:
            best, nearest = d, (qx, qy)
        if n >= 3:
            cross = ex * (py - ay) - ey * (px - ax)  # > 0: left of the edge (inside)
            if cross < 0.0:
                inside = False
            elif length2 > 1e-12:
                margin = min(margin, cross / math.sqrt(length2))
    if inside:
        return -margin, point
    return best, nearest


def sole_outside_m(point_xy: np.ndarray, ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray) -> float:
    """Signed distance of a horizontal point from one foot's sole: > 0 outside, < 0 inside [m]."""
    return outside_distance_m(point_xy, convex_hull_xy(sole_corners_world(ankle_world, foot_quat_wxyz)[:, :2]))[0]

"""Rotation helpers.

Convention, stated once for the whole package: quaternions are arrays ``(w, x, y, z)`` (scalar first), unit norm,
acting on column vectors (``R @ v``). Rotation vectors ("log maps") are axis * angle [rad]. PyBullet speaks
``(x, y, z, w)``: convert only at the engine boundary with :func:`wxyz_from_xyzw` / :func:`xyzw_from_wxyz`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

IDENTITY_WXYZ: Array = np.array([1.0, 0.0, 0.0, 0.0])


def wxyz_from_xyzw(q_xyzw) -> Array:
    """Reorder a PyBullet quaternion (x, y, z, w) into our (w, x, y, z)."""
    q = np.asarray(q_xyzw, dtype=float)
    return np.array([q[3], q[0], q[1], q[2]])


def xyzw_from_wxyz(q_wxyz) -> Array:
    """Reorder our quaternion (w, x, y, z) into PyBullet's (x, y, z, w)."""
    q = np.asarray(q_wxyz, dtype=float)
    return np.array([q[1], q[2], q[3], q[0]])


# Single quaternions and vectors are handled with Python floats (tolist): numpy's per-call overhead on 3- and
# 4-element arrays dominates the control tick otherwise.


def cross(a, b) -> Array:
    """a × b for 3-vectors, or row-wise for (n, 3) arrays (faster than np.cross on small inputs)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.ndim == 1 and b.ndim == 1:
        ax, ay, az = a.tolist()
        bx, by, bz = b.tolist()
        return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])
    out = np.empty(a.shape if a.shape == b.shape else np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def normalize(q: Array) -> Array:
    return _normalized(*np.asarray(q, dtype=float).tolist())


def _normalized(w: float, x: float, y: float, z: float, positive_w: bool = False) -> Array:
    """(w, x, y, z) divided by its norm (the identity if it has none), negated to w >= 0 if ``positive_w``."""
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if not math.isfinite(n) or n < 1e-12:
        return IDENTITY_WXYZ.copy()
    if positive_w and w < 0:  # -(w / n) is w / -n exactly
        n = -n
    return np.array([w / n, x / n, y / n, z / n])


def multiply(a: Array, b: Array) -> Array:
    """Hamilton product a ⊗ b (apply b first, then a)."""
    aw, ax, ay, az = np.asarray(a, dtype=float).tolist()
    bw, bx, by, bz = np.asarray(b, dtype=float).tolist()
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


_CONJUGATE_SIGNS = np.array([1.0, -1.0, -1.0, -1.0])
_WORLD_UP = np.array([0.0, 0.0, 1.0])
# heading_from_quat: the body x axis's heading up to this pitch, the twist about the vertical from the second on [deg]
HEADING_FORWARD_PITCH_DEG = 45.0
HEADING_TWIST_PITCH_DEG = 75.0
_HEADING_FORWARD_LENGTH = math.cos(math.radians(HEADING_FORWARD_PITCH_DEG))
_HEADING_TWIST_LENGTH = math.cos(math.radians(HEADING_TWIST_PITCH_DEG))
# ... and the x axis's heading wherever q's tilt (its swing from the vertical) exceeds HEADING_TWIST_MAX_TILT_DEG: a
# body upside down has no twist of its own (w² + z² = cos²(tilt / 2))
HEADING_TWIST_MAX_TILT_DEG = 100.0
_HEADING_TWIST_MIN_COS2 = math.cos(math.radians(HEADING_TWIST_MAX_TILT_DEG / 2.0)) ** 2


def conjugate(q: Array) -> Array:
    return np.asarray(q, dtype=float) * _CONJUGATE_SIGNS


def matrix_from_quat(q: Array) -> Array:
    """3x3 rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def quat_from_matrix(R: Array) -> Array:
    """Unit quaternion (w, x, y, z) with w >= 0 of a rotation matrix (Shepperd's method)."""
    return quat_from_matrix_rows(*np.asarray(R, dtype=float).tolist())


def quat_from_matrix_rows(r0, r1, r2) -> Array:
    """:func:`quat_from_matrix` of the matrix with rows r0, r1, r2 (sequences of three floats)."""
    m00, m01, m02 = r0
    m10, m11, m12 = r1
    m20, m21, m22 = r2
    tr = m00 + m11 + m22
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = (0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s)
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = ((m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s)
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s)
    return _normalized(*q, positive_w=True)


def rotate(q: Array, v: Array) -> Array:
    """Rotate vector v [any unit] by quaternion q: v + 2w (u × v) + 2 u × (u × v), u the vector part."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    vx, vy, vz = np.asarray(v, dtype=float).tolist()
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return np.array([vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)])


def quat_from_axis_angle(axis: Array, angle_rad: float) -> Array:
    x, y, z = np.asarray(axis, dtype=float).tolist()
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-12:
        return IDENTITY_WXYZ.copy()
    h = 0.5 * float(angle_rad)
    k = math.sin(h) / n
    return np.array([math.cos(h), k * x, k * y, k * z])


def quat_from_rotvec(rv: Array) -> Array:
    x, y, z = np.asarray(rv, dtype=float).tolist()
    angle = math.sqrt(x * x + y * y + z * z)
    if angle < 1e-12:
        return normalize(np.array([1.0, 0.5 * x, 0.5 * y, 0.5 * z]))
    k = math.sin(0.5 * angle) / angle
    return np.array([math.cos(0.5 * angle), k * x, k * y, k * z])


def rotvec_from_quat(q: Array) -> Array:
    """Log map: rotation vector [rad] of the shortest rotation equal to q (q and -q give the same)."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return np.array([2.0 * x, 2.0 * y, 2.0 * z])
    k = 2.0 * math.atan2(s, w) / s
    return np.array([k * x, k * y, k * z])


def slerp(q0: Array, q1: Array, t: float) -> Array:
    """Spherical interpolation from q0 (t = 0) to q1 (t = 1) along the shorter arc."""
    q1 = q1 if float(np.dot(q0, q1)) >= 0 else -q1
    d = multiply(conjugate(q0), q1)
    return normalize(multiply(q0, quat_from_rotvec(t * rotvec_from_quat(d))))


def yaw_from_quat(q: Array) -> float:
    """Heading [rad] about world z of the body x axis of q."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    return math.atan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))


def heading_from_quat(q: Array) -> float:
    """Heading [rad] of q about world z, in (-π, π].

    While the body x axis is within HEADING_FORWARD_PITCH_DEG of the horizontal, or q is tilted beyond
    HEADING_TWIST_MAX_TILT_DEG from the upright (a body upside down has no turn about the vertical of its own): the
    heading of the x axis, as :func:`yaw_from_quat` (the yaw of q's z-y-x Euler angles). As the x axis nears the
    vertical (a trunk bent over in a spin), its horizontal part shrinks and turns with the tilt, not with
    the turn, half a turn as it passes the vertical; from HEADING_TWIST_PITCH_DEG on: the turn of q about the
    vertical (its twist, :func:`twist_angle`), which stays defined there. Between the two: the direction of the
    blend of their unit vectors, the x axis's in proportion to its horizontal length and to its agreement with the
    twist (none where it points back, past the vertical)."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    fx, fy = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z)  # the body x axis's horizontal part
    length = math.hypot(fx, fy)
    if length >= _HEADING_FORWARD_LENGTH or w * w + z * z < _HEADING_TWIST_MIN_COS2:
        return math.atan2(fy, fx)
    twist = twist_angle(q, _WORLD_UP)
    share = min((length - _HEADING_TWIST_LENGTH) / (_HEADING_FORWARD_LENGTH - _HEADING_TWIST_LENGTH), 1.0)
    if share <= 0.0:
        return twist
    tx, ty = math.cos(twist), math.sin(twist)
    ux, uy = fx / length, fy / length
    share *= max(ux * tx + uy * ty, 0.0)  # none of an x axis that points back (past the vertical)
    return math.atan2(share * uy + (1.0 - share) * ty, share * ux + (1.0 - share) * tx)


def batch_heading_from_quat(q: Array) -> Array:
    """:func:`heading_from_quat` of each row of ``q`` (n, 4) [rad]."""
    w, x, y, z = np.asarray(q, dtype=float).T
    fx, fy = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z)
    length = np.hypot(fx, fy)
    sign = np.where(w < 0, -1.0, 1.0)
    twist = np.where((np.abs(w) < 1e-12) & (np.abs(z) < 1e-12), 0.0, 2.0 * np.arctan2(sign * z, sign * w))
    share = np.clip((length - _HEADING_TWIST_LENGTH) / (_HEADING_FORWARD_LENGTH - _HEADING_TWIST_LENGTH), 0.0, 1.0)
    tx, ty = np.cos(twist), np.sin(twist)
    unit = np.maximum(length, 1e-300)
    ux, uy = fx / unit, fy / unit
    share = share * np.maximum(ux * tx + uy * ty, 0.0)
    blend = np.arctan2(share * uy + (1.0 - share) * ty, share * ux + (1.0 - share) * tx)
    forward = (length >= _HEADING_FORWARD_LENGTH) | (w * w + z * z < _HEADING_TWIST_MIN_COS2)
    return np.where(forward, np.arctan2(fy, fx), np.where(share <= 0.0, twist, blend))


def quat_from_yaw(yaw_rad: float) -> Array:
    return quat_from_axis_angle(_WORLD_UP, yaw_rad)


def swing_twist(q: Array, axis: Array) -> tuple[Array, Array]:
    """Split q = swing ⊗ twist, twist being the rotation of q about ``axis`` (unit, in q's frame)."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    ax, ay, az = np.asarray(axis, dtype=float).tolist()
    p = x * ax + y * ay + z * az
    n = math.sqrt(w * w + p * p * (ax * ax + ay * ay + az * az))
    if n < 1e-12:
        tw, tx, ty, tz = 1.0, 0.0, 0.0, 0.0
    else:
        tw, tx, ty, tz = w / n, p * ax / n, p * ay / n, p * az / n
    # swing = q ⊗ conj(twist)
    swing = np.array([w * tw + x * tx + y * ty + z * tz, -w * tx + x * tw - y * tz + z * ty,
                      -w * ty + x * tz + y * tw - z * tx, -w * tz - x * ty + y * tx + z * tw])
    return swing, np.array([tw, tx, ty, tz])


def twist_angle(q: Array, axis: Array) -> float:
    """Signed twist angle [rad] of q about the unit ``axis``."""
    w, x, y, z = np.asarray(q, dtype=float).tolist()
    ax, ay, az = np.asarray(axis, dtype=float).tolist()
    p = x * ax + y * ay + z * az
    if abs(w) < 1e-12 and abs(p) < 1e-12:
        return 0.0
    if w < 0:
        w, p = -w, -p
    return 2.0 * math.atan2(p, w)


def rotation_between(a: Array, b: Array) -> Array:
    """Shortest rotation taking direction a onto direction b."""
    a = np.asarray(a, dtype=float) / np.linalg.norm(a)
    b = np.asarray(b, dtype=float) / np.linalg.norm(b)
    c = cross(a, b)
    d = float(np.dot(a, b))
    if d < -1 + 1e-9:
        ortho = cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(ortho) < 1e-6:
            ortho = cross(a, [0.0, 1.0, 0.0])
        return quat_from_axis_angle(ortho, np.pi)
    return normalize(np.array([1.0 + d, c[0], c[1], c[2]]))


def align_sign(q: Array, reference: Array) -> Array:
    """Return q or -q, whichever is closer to ``reference`` (double cover q ≡ -q)."""
    return q if float(np.dot(q, reference)) >= 0 else -q


# ---- batched versions for the per-physics-step controller: arrays of shape (n, 4) / (n, 3) --------------------
def _product_tensor() -> Array:
    """(16, 4) K with a ⊗ b = (a b^T flattened) @ K: the Hamilton product as one bilinear map."""
    k = np.zeros((4, 4, 4))
    basis = np.eye(4)
    for i in range(4):
        for j in range(4):
            k[i, j] = multiply(basis[i], basis[j])
    return k.reshape(16, 4)


_PRODUCT = _product_tensor()
# (16, 9): the rotation matrix of a unit quaternion from its outer product q q^T (the diagonal entries use
# w² + x² - y² - z² = 1 - 2 (y² + z²) for a unit q).
_matrix_terms = np.zeros((4, 4, 9))
for _r, _terms in enumerate([
    [(0, 0, 1), (1, 1, 1), (2, 2, -1), (3, 3, -1)], [(1, 2, 2), (0, 3, -2)], [(1, 3, 2), (0, 2, 2)],
    [(1, 2, 2), (0, 3, 2)], [(0, 0, 1), (1, 1, -1), (2, 2, 1), (3, 3, -1)], [(2, 3, 2), (0, 1, -2)],
    [(1, 3, 2), (0, 2, -2)], [(2, 3, 2), (0, 1, 2)], [(0, 0, 1), (1, 1, -1), (2, 2, -1), (3, 3, 1)],
]):
    for _i, _j, _c in _terms:
        _matrix_terms[_i, _j, _r] = _c
_MATRIX = _matrix_terms.reshape(16, 9)


def batch_multiply(a: Array, b: Array) -> Array:
    """Hamilton product of each row, (n, 4) x (n, 4) -> (n, 4) (three numpy calls: small n is the common case)."""
    return (a[:, :, None] * b[:, None, :]).reshape(len(a), 16) @ _PRODUCT


def batch_conjugate(q: Array) -> Array:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def batch_rotvec(q: Array) -> Array:
    """Log map of each row (shortest rotation), (n, 4) -> (n, 3) [rad]."""
    w, v = q[:, 0], q[:, 1:]
    s = np.sqrt(np.einsum("ij,ij->i", v, v))
    angle = 2.0 * np.arctan2(s, np.abs(w))  # of q or -q, whichever has w >= 0
    scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-12), 2.0)
    return v * np.copysign(scale, w)[:, None]


def batch_quat_from_rotvec(v: Array) -> Array:
    """Exp map of each row, (n, 3) [rad] -> (n, 4)."""
    angle = np.linalg.norm(v, axis=1)
    half = 0.5 * angle
    # sin(θ/2)/θ, and its limit 1/2 at θ = 0
    k = np.where(angle > 1e-12, np.sin(half) / np.maximum(angle, 1e-12), 0.5)
    return np.column_stack([np.cos(half), v * k[:, None]])


def batch_align_sign(q: Array, reference: Array) -> Array:
    """Each row of q or its negative, whichever is closer to the same row of ``reference``."""
    return np.where(np.add.reduce(q * reference, axis=1)[:, None] < 0, -q, q)  # (einsum's dispatch costs more)


def batch_slerp_rotvec(q0: Array, q1: Array) -> Array:
    """(n, 3) rotation vectors [rad] that take each row of q0 to q1 along the shorter arc (the slerp's path)."""
    return batch_rotvec(batch_multiply(batch_conjugate(q0), batch_align_sign(q1, q0)))


def batch_slerp_along(q0: Array, rotvec: Array, t: float) -> Array:
    """Each row of q0 turned by the fraction t of its :func:`batch_slerp_rotvec`, (n, 4)."""
    q = batch_multiply(q0, batch_quat_from_rotvec(t * rotvec))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def batch_slerp(q0: Array, q1: Array, t: float) -> Array:
    """:func:`slerp` of each row, (n, 4)."""
    return batch_slerp_along(q0, batch_slerp_rotvec(q0, q1), t)


def batch_matrix_from_quat(q: Array) -> Array:
    """Rotation matrices of each row (unit quaternions), (n, 4) -> (n, 3, 3)."""
    return ((q[:, :, None] * q[:, None, :]).reshape(len(q), 16) @ _MATRIX).reshape(len(q), 3, 3)

"""Style feature extractor (Sec. 5.2): F = {T_l, T_r, N_l, N_r, P_cl, P_cr, H}.

* T: twist of the ankle (foot relative to shank) about the lower-leg axis [rad];
* N: unit normal of the leg motion plane, ``(knee - hip) × (ankle - knee)``, pointing left for a knee bent
  forward; undefined for a straight leg, where the previous normal (or the pelvis's left axis) is kept;
* P_c: vector from the COM to each ankle [m];
* H: heading of the root, the yaw of the pelvis [rad]; with the trunk bent over (a spin), its turn about the
  vertical (rotations.heading_from_quat): the heading of its forward axis turns with the tilt there, not the turn.
The same extractor serves the operator and the character, so their features can be compared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot

_SHANK_AXIS = np.array([0.0, 0.0, 1.0])  # long axis of a shank in canonical segment axes
_MIN_PLANE_SINE = 0.15  # below this (knee bent < ~9 deg) the leg is straight and its plane undefined


@dataclass(frozen=True)
class StyleFeatures:
    T_l: float
    T_r: float
    N_l: np.ndarray
    N_r: np.ndarray
    P_cl: np.ndarray
    P_cr: np.ndarray
    H: float

    def as_row(self) -> list[float]:
        return [self.T_l, self.T_r, *self.N_l, *self.N_r, *self.P_cl, *self.P_cr, self.H]

    @staticmethod
    def from_row(row: np.ndarray) -> StyleFeatures:
        """The inverse of :meth:`as_row` (ROW_NAMES order); the vectors are views of ``row``."""
        return StyleFeatures(float(row[0]), float(row[1]), row[2:5], row[5:8], row[8:11], row[11:14], float(row[14]))


ROW_NAMES = ["T_l", "T_r", "N_l_x", "N_l_y", "N_l_z", "N_r_x", "N_r_y", "N_r_z", "P_cl_x", "P_cl_y", "P_cl_z",
             "P_cr_x", "P_cr_y", "P_cr_z", "H"]


def leg_plane_normal(hip, knee, ankle, fallback: np.ndarray) -> np.ndarray:
    hx, hy, hz = np.asarray(hip, dtype=float).tolist()  # Python floats: per control tick, two legs
    kx, ky, kz = np.asarray(knee, dtype=float).tolist()
    ax_, ay_, az_ = np.asarray(ankle, dtype=float).tolist()
    a = (kx - hx, ky - hy, kz - hz)
    b = (ax_ - kx, ay_ - ky, az_ - kz)
    nx, ny, nz = a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]
    s = math.sqrt(nx * nx + ny * ny + nz * nz)
    if s < _MIN_PLANE_SINE * math.hypot(*a) * math.hypot(*b) or s < 1e-9:
        return np.asarray(fallback, dtype=float)
    # A knee bends forward: the normal points to the body's left. A reversed normal is sensor noise on an
    # almost straight leg (or a hyper-extended knee); keep the hemisphere of the fallback (the pelvis's left).
    fx, fy, fz = np.asarray(fallback, dtype=float).tolist()
    sign = 1.0 if nx * fx + ny * fy + nz * fz >= 0 else -1.0
    return np.array([sign * nx / s, sign * ny / s, sign * nz / s])


class StyleExtractor:
    def __call__(self, hip: dict[str, np.ndarray], knee: dict[str, np.ndarray], ankle: dict[str, np.ndarray],
                 shank_quat: dict[str, np.ndarray], foot_quat: dict[str, np.ndarray], com: np.ndarray,
                 pelvis_quat: np.ndarray) -> StyleFeatures:
        left_axis = rot.rotate(pelvis_quat, np.array([0.0, 1.0, 0.0]))
        T, N, P = {}, {}, {}
        for s in ("left", "right"):
            q_ankle = rot.multiply(rot.conjugate(shank_quat[s]), foot_quat[s])
            T[s] = rot.twist_angle(q_ankle, _SHANK_AXIS)
            N[s] = leg_plane_normal(hip[s], knee[s], ankle[s], left_axis)
            P[s] = np.asarray(ankle[s]) - np.asarray(com)
        return StyleFeatures(T["left"], T["right"], N["left"], N["right"], P["left"], P["right"],
                             rot.heading_from_quat(pelvis_quat))


def style_rows(hip: np.ndarray, knee: np.ndarray, ankle: np.ndarray, shank_quat: np.ndarray, foot_quat: np.ndarray,
               com: np.ndarray, pelvis_quat: np.ndarray) -> np.ndarray:
    """:class:`StyleExtractor` over many instants at once, as rows in ``ROW_NAMES`` order, (n, 15).

    ``hip``, ``knee``, ``ankle``: (n, 2, 3) world positions [m], left then right; ``shank_quat``, ``foot_quat``:
    (n, 2, 4) world orientations (wxyz, canonical segment axes); ``com`` (n, 3) [m]; ``pelvis_quat`` (n, 4). Used to
    fill a run's log after the run, off the control tick."""
    n = len(com)
    out = np.empty((n, len(ROW_NAMES)))
    # T: twist of conj(shank) ⊗ foot about the shank's long axis (z), as rotations.twist_angle.
    q = rot.batch_multiply(rot.batch_conjugate(shank_quat.reshape(-1, 4)), foot_quat.reshape(-1, 4))
    w, p = q[:, 0], q[:, 3]
    sign = np.where(w < 0, -1.0, 1.0)
    twist = np.where((np.abs(w) < 1e-12) & (np.abs(p) < 1e-12), 0.0, 2.0 * np.arctan2(sign * p, sign * w))
    out[:, 0:2] = twist.reshape(n, 2)
    # N: leg plane normals, with the pelvis's left axis as the fallback and hemisphere (leg_plane_normal).
    left = rot.batch_matrix_from_quat(pelvis_quat)[:, :, 1]  # (n, 3)
    a, b = knee - hip, ankle - knee
    normal = rot.cross(a, b)  # (n, 2, 3)
    s = np.linalg.norm(normal, axis=2)
    straight = (s < _MIN_PLANE_SINE * np.linalg.norm(a, axis=2) * np.linalg.norm(b, axis=2)) | (s < 1e-9)
    unit = normal / np.maximum(s, 1e-300)[:, :, None]
    unit = np.where((np.einsum("nsk,nk->ns", unit, left) >= 0)[:, :, None], unit, -unit)
    normals = np.where(straight[:, :, None], left[:, None, :], unit)
    out[:, 2:5], out[:, 5:8] = normals[:, 0], normals[:, 1]
    # P_c: COM to each ankle; H: the pelvis's heading (rotations.heading_from_quat).
    out[:, 8:11], out[:, 11:14] = ankle[:, 0] - com, ankle[:, 1] - com
    out[:, 14] = rot.batch_heading_from_quat(pelvis_quat)
    return out

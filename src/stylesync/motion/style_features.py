"""Style feature extractor (Sec. 5.2): F = {T_l, T_r, N_l, N_r, P_cl, P_cr, H}.

* T: twist of the ankle (foot relative to shank) about the lower-leg axis [rad];
* N: unit normal of the leg motion plane, ``(knee - hip) × (ankle - knee)``, pointing left for a knee bent
  forward; undefined for a straight leg, where the previous normal (or the pelvis's left axis) is kept;
* P_c: vector from the COM to each ankle [m];
* H: heading of the root, the yaw of the pelvis [rad].
The same extractor serves the operator and the character, so their features can be compared.
"""

from __future__ import annotations

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


ROW_NAMES = ["T_l", "T_r", "N_l_x", "N_l_y", "N_l_z", "N_r_x", "N_r_y", "N_r_z", "P_cl_x", "P_cl_y", "P_cl_z",
             "P_cr_x", "P_cr_y", "P_cr_z", "H"]


def leg_plane_normal(hip, knee, ankle, fallback: np.ndarray) -> np.ndarray:
    a = np.asarray(knee) - np.asarray(hip)
    b = np.asarray(ankle) - np.asarray(knee)
    n = rot.cross(a, b)
    s = np.linalg.norm(n)
    if s < _MIN_PLANE_SINE * np.linalg.norm(a) * np.linalg.norm(b) or s < 1e-9:
        return np.asarray(fallback, dtype=float)
    n = n / s
    # A knee bends forward: the normal points to the body's left. A reversed normal is sensor noise on an
    # almost straight leg (or a hyper-extended knee); keep the hemisphere of the fallback (the pelvis's left).
    return n if float(n @ np.asarray(fallback)) >= 0 else -n


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
                             rot.yaw_from_quat(pelvis_quat))

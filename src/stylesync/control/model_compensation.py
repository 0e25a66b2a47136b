"""Model-based torque compensation for the CR-VC (Sec. 6.3, Eq. 20-23).

* IPM ankle torque (Eq. 20): ``τ_am = m_C g d_C``, d_C the horizontal offset of the (desired) COM from the
  stance ankle, i.e. the torque that holds an inverted pendulum leaning like the operator. As a vector on the
  ankle joint: ``τ = -(c_d - a) × (m_C g ẑ)`` (horizontal part), shared by the stance feet.
* LIPM time-synchronising force (Eq. 21-23): in single stance the character COM is made to accelerate like the
  operator's, scaled by dynamic similarity: desired ``p̈_CC = p̈_CH h_C / h_H`` (Eq. 22 as in the notes: the text's
  first derivative is a typo for the second), with both accelerations from the LIPM (Eq. 21):
  ``f_cro = m_C g (d_aH / h_H · h_C / h_H - d_aC / h_C)`` (Eq. 23), d_a the horizontal COM offset from the
  stance ankle (the CoP).
"""

from __future__ import annotations

import math

import numpy as np

from stylesync import rotations as rot
from stylesync.control.gravity_compensation import ANKLE_JOINT
from stylesync.control.support import support_point
from stylesync.model.character import JOINTS
from stylesync.motion.bounds import BoundsMonitor, lipm_force_bound_n
from stylesync.motion.reference import LipmMap


def ipm_ankle_moments(com_desired: np.ndarray, ankle_pos: dict[str, np.ndarray], stance_weight: dict[str, float],
                      mass_kg: float, gravity_mps2: float, foot_yaw_rad: dict[str, float] | None = None) -> np.ndarray:
    """Eq. 20 as world moments on the stance ankle joints, (n_joints, 3) [N·m].

    d_C is taken from each foot's support point (support.support_point) rather than from each ankle:
    identical in single stance; in double stance it keeps the two ankles from pushing the body sideways against
    each other (the paper's single-ankle form would put ±m g w/2 lateral torques on feet that already carry
    their share directly below them). With the feet's headings the point is kept on the sole: a larger ankle
    torque than the foot can pass to the ground only rolls the foot.
    """
    moment = np.zeros((len(JOINTS), 3))
    for side, p in support_point(com_desired, ankle_pos, stance_weight, foot_yaw_rad).items():
        weight = np.array([0.0, 0.0, stance_weight[side] * mass_kg * gravity_mps2])
        d = p - ankle_pos[side]
        d[2] = 0.0  # horizontal distance d_C only (Eq. 20)
        moment[ANKLE_JOINT[side]] = -rot.cross(d, weight)
    return moment


def lipm_sync_force(d_a_human: np.ndarray, h_human_m: float, d_a_char: np.ndarray, h_char_m: float,
                    mass_kg: float, gravity_mps2: float) -> np.ndarray:
    """Eq. 23: horizontal force [N] (z component 0)."""
    f = mass_kg * gravity_mps2 * (np.asarray(d_a_human) / h_human_m * (h_char_m / h_human_m)
                                  - np.asarray(d_a_char) / h_char_m)
    f = np.array([f[0], f[1], 0.0])
    return f


def synchronised_tracking_force_n(lipm: LipmMap, mass_kg: float, gravity_mps2: float) -> float:
    """|f_cro| [N] that Eq. 23 asks of a character that tracks the operator exactly (d_aC = d_aH h_C / h_H):
    ``m_C g |d_aH| |h_C - h_H| / h_H²``. It depends on the operator's motion alone: the ankle torque it implies
    (Eq. 25) is what his motion asks of the character's foot, the counterpart of Eq. 28 for the COM."""
    d = math.hypot(float(lipm.d_a_human[0]), float(lipm.d_a_human[1]))
    return mass_kg * gravity_mps2 * d * abs(lipm.h_char_m - lipm.h_human_m) / lipm.h_human_m ** 2


def bounded_lipm_sync_force(lipm: LipmMap, mass_kg: float, gravity_mps2: float, force_limit_n: float,
                            enforce: bool, bounds: BoundsMonitor, time_s: float) -> np.ndarray:
    """Eq. 23 for ``lipm``, clamped to Eq. 26's bound when ``enforce``.

    Two things are reported. The operator exceeds the movement bound (``lipm_force``) when the force his motion
    asks of an exactly tracking character (:func:`synchronised_tracking_force_n`) exceeds the bound. The force
    actually applied also carries the character's own lag behind him (its d_aC), so its clamp (``lipm_clamped``)
    is counted apart: it says how hard the controller works, not what the operator did.
    """
    f = lipm_sync_force(lipm.d_a_human, lipm.h_human_m, lipm.d_a_char, lipm.h_char_m, mass_kg, gravity_mps2)
    limit = min(force_limit_n, lipm_force_bound_n(mass_kg, gravity_mps2, lipm.h_char_m))
    demand = synchronised_tracking_force_n(lipm, mass_kg, gravity_mps2)
    bounds.report("lipm_force", demand > limit, time_s, "his motion asks |f_cro| %.0f N > %.0f N (Eq. 26)", demand,
                  limit)
    mag = math.hypot(float(f[0]), float(f[1]))  # (f has no z component)
    exceeded = mag > limit and enforce
    bounds.report("lipm_clamped", exceeded, time_s, "|f_cro| %.0f N clamped to %.0f N", mag, limit)
    return f * (limit / mag) if exceeded else f

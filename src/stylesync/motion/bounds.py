"""Movement boundedness of the CR-VC (Sec. 6.4, Eq. 24-28), computed every control tick.

* Eq. 24, double stance: the COM's horizontal offset d_C from the support centre must stay below
  ``min(L_f, W_f)``.
* Eq. 25-27, single stance: the ankle torque the LIPM force implies, ``τ_ca = f_cro h_C``, must stay below the
  foot-flip torque ``τ_flip = m_C g d_f``, d_f = min(L_f, W_f): |f_cro| is clamped to ``m_C g d_f / h_C``.
* Eq. 28: the step length is bounded by ``d_f / |h_C / h_H - 1|``. As printed the denominator is negative for a
  character smaller than its operator (h_C < h_H); we use its magnitude. The swing-foot target is clamped to
  the bound.
Violations are counted and logged (rate-limited) so the operator can be told.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from stylesync.model.character import FOOT_LENGTH_M, FOOT_WIDTH_M

log = logging.getLogger("stylesync.bounds")
FOOT_MIN_DIMENSION_M = min(FOOT_LENGTH_M, FOOT_WIDTH_M)  # d_f of Eq. 27 [m]
_LOG_INTERVAL_S = 1.0


def ds_com_bound_m() -> float:
    """Eq. 24 bound on d_C [m]."""
    return FOOT_MIN_DIMENSION_M


def lipm_force_bound_n(mass_kg: float, gravity_mps2: float, h_char_m: float) -> float:
    """Eq. 26-27: the largest |f_cro| [N] that does not flip the foot."""
    return mass_kg * gravity_mps2 * FOOT_MIN_DIMENSION_M / h_char_m


def step_length_bound_m(h_char_m: float, h_human_m: float) -> float:
    """Eq. 28 with |h_C / h_H - 1| [m]; infinite when the two are the same size."""
    denom = abs(h_char_m / h_human_m - 1.0)
    return float("inf") if denom < 1e-6 else FOOT_MIN_DIMENSION_M / denom


@dataclass
class BoundsMonitor:
    counts: dict[str, int] = field(default_factory=lambda: {"ds_com": 0, "lipm_force": 0, "step_length": 0})
    active: dict[str, bool] = field(default_factory=lambda: {"ds_com": False, "lipm_force": False,
                                                             "step_length": False})
    _last_log_s: dict[str, float] = field(default_factory=dict)

    def report(self, kind: str, exceeded: bool, time_s: float, detail: str) -> None:
        self.active[kind] = exceeded
        if not exceeded:
            return
        self.counts[kind] += 1
        if time_s - self._last_log_s.get(kind, -np.inf) >= _LOG_INTERVAL_S:
            self._last_log_s[kind] = time_s
            log.warning("t=%.2f s: operator exceeds movement bound (%s): %s", time_s, kind, detail)

"""Movement boundedness of the CR-VC (Sec. 6.4, Eq. 24-28), computed every control tick.

* Eq. 24, double stance: the COM's horizontal offset d_C from the support centre must stay below
  ``min(L_f, W_f)``.
* Eq. 25-27, single stance: the ankle torque the LIPM force implies, ``τ_ca = f_cro h_C``, must stay below the
  foot-flip torque ``τ_flip = m_C g d_f``, d_f = min(L_f, W_f): |f_cro| is clamped to ``m_C g d_f / h_C``.
* Eq. 28: the step length is bounded by ``d_f / |h_C / h_H - 1|``. As printed the denominator is negative for a
  character smaller than its operator (h_C < h_H); we use its magnitude. The swing-foot target is clamped to
  the bound.
Eq. 26 is checked on the operator's motion (model_compensation.synchronised_tracking_force_n): the force his
motion asks of a character that tracks him exactly. The clamp of the force actually applied, which also carries
the character's own lag, is counted apart (``lipm_clamped``) and is not an operator's bound.
Violations are counted (metrics.json, ``bound_violations``), logged at debug level and summarised once at the
end of a run (:meth:`BoundsMonitor.summary`), so that the operator is told without a line per second.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from stylesync.model.character import FOOT_LENGTH_M, FOOT_WIDTH_M

log = logging.getLogger("stylesync.bounds")
FOOT_MIN_DIMENSION_M = min(FOOT_LENGTH_M, FOOT_WIDTH_M)  # d_f of Eq. 27 [m]
_LOG_INTERVAL_S = 1.0
BOUND_KINDS = ("ds_com", "lipm_force", "step_length")  # the operator's movement bounds (Eq. 24, 26, 28)
CONTROLLER_KINDS = ("lipm_clamped",)  # the controller's own clamps, counted only


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
    """Per bound: ticks exceeded, whether it is exceeded now, and the first excess (time and detail)."""

    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(BOUND_KINDS + CONTROLLER_KINDS, 0))
    active: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(BOUND_KINDS + CONTROLLER_KINDS, False))
    first: dict[str, tuple[float, str]] = field(default_factory=dict)
    _last_log_s: dict[str, float] = field(default_factory=dict)

    def report(self, kind: str, exceeded: bool, time_s: float, detail: str, *args: float) -> None:
        """Whether the bound ``kind`` is exceeded at ``time_s``; ``detail % args`` says by how much (formatted only
        when it is exceeded: this runs at every control tick)."""
        self.active[kind] = exceeded
        if not exceeded:
            return
        if args:
            detail = detail % args
        self.counts[kind] += 1
        self.first.setdefault(kind, (time_s, detail))
        if time_s - self._last_log_s.get(kind, -np.inf) >= _LOG_INTERVAL_S:
            self._last_log_s[kind] = time_s
            log.debug("t=%.2f s: %s: %s", time_s, kind, detail)

    def summary(self, control_hz: float) -> str | None:
        """One line on the operator's bounds exceeded over a run (None if none was)."""
        parts = [f"{kind} {self.counts[kind] / control_hz:.2f} s from t={self.first[kind][0]:.2f} s "
                 f"({self.first[kind][1]})" for kind in BOUND_KINDS if self.counts[kind]]
        return "operator exceeded movement bounds: " + "; ".join(parts) if parts else None

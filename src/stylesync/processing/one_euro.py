"""The 1€ filter (Casiez, Roussel & Vogel, CHI 2012), the paper's "joint filter" (Sec. 4.3, Eq. 8).

Eq. 8 as printed computes the cut-off from the derivative of the *filtered* value at i+1, which is implicit. We
use the standard filter of Casiez et al.: the derivative of the input is estimated from the previous filtered
value and low-passed with its own cut-off ``d_cutoff``, then ``f_c = f_cmin + beta |dx|``, then
``x_flt = a x + (1 - a) x_flt_prev`` with ``a = 1 / (1 + tau / T_e)``, ``tau = 1 / (2 pi f_c)``: the same
first-order form as Eq. 8.
"""

from __future__ import annotations

import math

import numpy as np


def _alpha(cutoff_hz: np.ndarray | float, period_s: float) -> np.ndarray | float:
    tau = 1.0 / (2.0 * math.pi * cutoff_hz)  # Eq. 8, t = 1 / (2 pi f_C)
    return 1.0 / (1.0 + tau / period_s)  # Eq. 8, 1 / (1 + t / T_e)


class OneEuroFilter:
    """Element-wise 1€ filter on a vector sampled at a fixed period ``period_s`` [s]."""

    def __init__(self, period_s: float, min_cutoff_hz: float = 1.0, beta: float = 1.0, d_cutoff_hz: float = 1.0):
        if period_s <= 0 or min_cutoff_hz <= 0 or d_cutoff_hz <= 0 or beta < 0:
            raise ValueError("OneEuroFilter needs period_s > 0, min_cutoff_hz > 0, d_cutoff_hz > 0, beta >= 0")
        self.period_s = period_s
        self.min_cutoff_hz = min_cutoff_hz
        self.beta = beta
        self.d_cutoff_hz = d_cutoff_hz
        self._x: np.ndarray | None = None
        self._dx: np.ndarray | None = None
        self._dx0: np.ndarray | None = None

    def reset(self) -> None:
        self._x = None
        self._dx = None

    def prime(self, rate_per_s: np.ndarray) -> None:
        """The derivative the filter starts from at its first sample (default 0): a signal already moving at its
        first sample is then filtered with its cut-off of Eq. 8 from the start, not from f_cmin."""
        self._dx0 = np.asarray(rate_per_s, dtype=float).copy()

    def __call__(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if self._x is None or self._dx is None:
            self._x = x.copy()
            self._dx = self._dx0.copy() if self._dx0 is not None and self._dx0.shape == x.shape else np.zeros_like(x)
            return x.copy()
        dx = (x - self._x) / self.period_s
        a_d = _alpha(self.d_cutoff_hz, self.period_s)
        self._dx = a_d * dx + (1.0 - a_d) * self._dx
        cutoff = self.min_cutoff_hz + self.beta * np.abs(self._dx)  # Eq. 8, f_C = f_cmin + beta |dq|
        a = _alpha(cutoff, self.period_s)
        self._x = a * x + (1.0 - a) * self._x
        return self._x.copy()

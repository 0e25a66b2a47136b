"""The floor filter for the operator COM (Sec. 4.3), also used on the ankles the COM is retargeted against.

The paper sets "a threshold value for the floor range" of 0.01 m without defining the filter. We read it as a
dead band per axis: the output stays put while the input lies within +/- threshold of it, and otherwise follows
the input at the band's edge (no jump), so sensor jitter below the threshold never reaches the balance control.
"""

from __future__ import annotations

import numpy as np


class FloorFilter:
    def __init__(self, threshold_m: float = 0.01):
        if threshold_m < 0:
            raise ValueError(f"floor threshold must be >= 0 m, got {threshold_m}")
        self.threshold_m = threshold_m
        self._out: np.ndarray | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if self._out is None:
            self._out = x.copy()
            return x.copy()
        d = x - self._out
        excess = np.sign(d) * np.maximum(np.abs(d) - self.threshold_m, 0.0)
        self._out = self._out + excess
        return self._out.copy()

"""Time-varying interpolation of mocap frames to the control rate (Sec. 4.3, Eq. 7).

Eq. 7 as printed, ``q_{n,i+1} = (q_ref_{n+1} - q_{n,i}) k i + q_{n,i}`` with ``k = f_mcp / f_itp``, calls k "the
number of interpolations" although 16/133 < 1, and lets the factor k*i grow with i. We read it as: at control
step i after mocap frame n arrived, the output is the fraction ``min(k i, 1)`` of the way from the value held when
frame n arrived to the reference of frame n (the newest), so that the output reaches each new reference one
mocap period after it arrives. A new frame restarts the ramp from the current output (no jump). Quaternions are
interpolated by slerp on the same fraction.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot


def smooth_step(x: float) -> float:
    """0 -> 1 with zero slope at both ends (x clamped to [0, 1])."""
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


def smooth_step_slope(x: float) -> float:
    """d smooth_step / dx: 6 x (1 - x) within [0, 1], 0 outside."""
    return 6.0 * x * (1.0 - x) if 0.0 <= x <= 1.0 else 0.0


class LinearRamp:
    """Eq. 7 for a vector of scalars (positions [m], angles [rad])."""

    def __init__(self, mocap_hz: float, control_hz: float):
        self.k = mocap_hz / control_hz  # Eq. 7, k = f_mcp / f_itp
        self._start: np.ndarray | None = None
        self._target: np.ndarray | None = None
        self._out: np.ndarray | None = None
        self._i = 0

    def push(self, reference: np.ndarray) -> None:
        """A new mocap frame: ramp from the current output to ``reference``."""
        ref = np.array(reference, dtype=float)
        if self._out is None:
            self._out = ref.copy()
            self._start = ref.copy()
        else:
            self._start = self._out.copy()
        self._target = ref
        self._i = 0

    def step(self) -> np.ndarray:
        """The interpolated value for the next control step."""
        if self._out is None or self._start is None or self._target is None:
            raise ValueError("LinearRamp.step() before the first push()")
        self._i += 1
        frac = min(self.k * self._i, 1.0)
        self._out = self._start + (self._target - self._start) * frac
        return self._out.copy()


class SlerpRamp:
    """Eq. 7 for a set of unit quaternions (n, 4), wxyz."""

    def __init__(self, mocap_hz: float, control_hz: float):
        self.k = mocap_hz / control_hz
        self._start: np.ndarray | None = None
        self._rotvec_rad = np.zeros((0, 3))
        self._out: np.ndarray | None = None
        self._i = 0

    def push(self, reference: np.ndarray) -> None:
        ref = np.array(reference, dtype=float)
        if self._out is None:
            self._out = ref.copy()
        self._start = self._out.copy()
        self._rotvec_rad = rot.batch_slerp_rotvec(self._start, ref)  # towards ref, fixed until the next frame
        self._i = 0

    def step(self) -> np.ndarray:
        if self._out is None or self._start is None:
            raise ValueError("SlerpRamp.step() before the first push()")
        self._i += 1
        frac = min(self.k * self._i, 1.0)
        self._out = rot.batch_slerp_along(self._start, self._rotvec_rad, frac)
        return self._out.copy()

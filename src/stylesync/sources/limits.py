"""Physical limits every recorded or streamed operator frame is checked against before it enters the pipeline.

A frame interval outside [MIN_FRAME_INTERVAL_S, MAX_FRAME_INTERVAL_S] is not a motion-capture rate (a BVH
``Frame Time`` of 1e-9 s or 1e300 s); a position farther than MAX_DISTANCE_M from where the recording starts is
not a person in a room or on a street; a recording longer than MAX_RECORDING_S is not one session.
"""

from __future__ import annotations

import numpy as np

MIN_FRAME_INTERVAL_S = 1e-4
MAX_FRAME_INTERVAL_S = 1.0
MAX_DISTANCE_M = 1000.0
MAX_RECORDING_S = 86_400.0


def frame_interval_problem(dt_s: float, max_s: float = MAX_FRAME_INTERVAL_S) -> str | None:
    """Why ``dt_s`` is no frame interval, or None. ``max_s``: a source whose frames may be apart by more than a
    sampling interval (a tracker that lost the person for a while) passes a larger bound."""
    if not (MIN_FRAME_INTERVAL_S <= dt_s <= max_s):
        return f"frame interval {dt_s:.3g} s outside [{MIN_FRAME_INTERVAL_S:g}, {max_s:g}] s"
    return None


def distance_problem(pos_m: np.ndarray, start_m: np.ndarray) -> str | None:
    """Why positions ``pos_m`` (..., 3) are too far from ``start_m`` (3,), or None."""
    d = float(np.max(np.linalg.norm(np.asarray(pos_m, dtype=float) - start_m, axis=-1)))
    if not d <= MAX_DISTANCE_M:
        return f"a joint {d:.3g} m from where the recording starts (limit {MAX_DISTANCE_M:g} m)"
    return None

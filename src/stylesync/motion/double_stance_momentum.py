"""Momentum kept through a double stance: a character slower than its operator is not braked between two steps.

Opt-in (MotionConfig.double_stance_keeps_momentum_m, off by default): with it the walks cover more of the operator's
way, but the built-in walk's character steps on its own and falls out of step with him (docs/decisions.md, "Momentum
kept through a double stance").

In the operator's double stance the COM target of Eq. 10 is his fraction of the way between his feet, mapped onto
the character's feet, and the desired COM velocity (Eq. 19) is that target's rate. A character whose steps are
shorter than his (scaled) sees that target move slower than he does: the rate is the fraction's rate times its
own, shorter step, and it is nearly zero once his COM is over his front foot. The COM task then braked the character
at every double stance of a walk, by 50-130 N (traced on the built-in walk, seed 0), and the walk settled into a
gait as slow as its short steps (docs/decisions.md, "Following the operator over the ground").

Here, along the operator's scaled COM velocity ``u`` (speed ``s``), the desired velocity is not below the
character's own, up to his: ``v_d·u`` becomes ``max(v_d·u, min(s, v_c·u))``, the other components are kept. So the
double stance does not brake a character moving his way slower than he does, and never asks it to go faster than
it goes or than he goes; a target ahead of it (the position term) still pulls. The caller applies it only in a
gait's double stance (:func:`moves_between_feet`: not in a crouch before a leap or a sway on both feet), and only
while the character's capture point is near its support polygon (MotionConfig.double_stance_keeps_momentum_m): a
body already beyond what its feet can stop is braked as before.
"""

from __future__ import annotations

import math

import numpy as np

_MIN_SPEED_MPS = 1e-6  # an operator slower than this has no direction to keep [m/s]
# A double stance in which the operator's COM moves within this angle of the line through his ankles is a gait's
# [deg]
GAIT_AXIS_DEG = 45.0
_GAIT_AXIS_COS = math.cos(math.radians(GAIT_AXIS_DEG))


def moves_between_feet(com_vel_world: np.ndarray, left_ankle_world: np.ndarray,
                       right_ankle_world: np.ndarray) -> bool:
    """Whether a COM moving at ``com_vel_world`` [m/s] moves from one foot towards the other, as in a walk's double
    stance: its horizontal velocity within GAIT_AXIS_DEG of the line through the ankles [m], either way (not across
    it, as in a crouch or a sway on both feet, nor while it stands still)."""
    v = np.asarray(com_vel_world, dtype=float)[:2]
    d = np.asarray(left_ankle_world, dtype=float)[:2] - np.asarray(right_ankle_world, dtype=float)[:2]
    nv, nd = float(np.hypot(v[0], v[1])), float(np.hypot(d[0], d[1]))
    return nv > _MIN_SPEED_MPS and nd > 1e-6 and abs(float(v @ d)) >= _GAIT_AXIS_COS * nv * nd


def kept_com_velocity(rate_world: np.ndarray, operator_vel_world: np.ndarray,
                      character_vel_world: np.ndarray) -> np.ndarray:
    """The desired COM velocity (3,) [m/s]: ``rate_world`` (the COM target's rate, (3,)) with its component along
    the operator's scaled horizontal COM velocity ``operator_vel_world`` ((2,) or (3,)) raised to the character's
    own (``character_vel_world``), at most to the operator's speed; unchanged when the operator stands."""
    out = np.array(rate_world, dtype=float)
    his = np.asarray(operator_vel_world, dtype=float)[:2]
    speed = float(np.hypot(his[0], his[1]))
    if speed < _MIN_SPEED_MPS:
        return out
    u = his / speed
    along = float(u @ out[:2])
    own = float(u @ np.asarray(character_vel_world, dtype=float)[:2])
    kept = max(along, min(speed, own))
    out[:2] += (kept - along) * u
    return out

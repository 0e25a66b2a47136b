"""Steps to where the operator stands: the character stops where he stops.

Every target of the motion stage is relative to the character's own feet (Eq. 10 anchors the COM on them), and a
character whose steps fell short of his comes to rest where its feet are: behind him, by as much as it lost while he
walked (a walk that ends 0.5-0.8 m short, a lunge of his that it followed by half). The path feedback
(path_feedback.py) corrects that distance through the landings of his steps; once he stands there are none, and the
capture bound keeps the COM target within what the feet support, so no lean of the targets turns into a step either.

When he has stood still (his stance FSM in double stance, his COM and his feet at rest) and the character stands on
both feet with its capture point within their support, each of its feet has a place: his foot's, on the character's
path (``PathReference.on_path_xy``: scaled about his first pelvis ground point onto the character's), the two at
least ``MIN_FOOT_SEPARATION_M`` apart sideways. A foot lands at its place, at most a step's reach
(``MotionConfig.rest_step_reach_m``) from where it lifts off and from the other foot, and never across that
(:func:`recovery_step.not_across`); the foot whose landing takes it the most nearer its place steps, if that is at
least ``MotionConfig.rest_step_min_m``. Before it lifts, the COM target moves over the other foot (a weight shift)
until the capture point is ``WEIGHT_OVER_SOLE_M`` inside that sole; during the step it stays there; after the landing
the targets are anchored on the new feet again (Eq. 10), and the next step follows the same way. A character whose
feet are within that distance of his stays where it is.
"""

from __future__ import annotations

import math

import numpy as np

from stylesync.model.character import FOOT_WIDTH_M, OTHER_SIDE
from stylesync.motion.recovery_step import MIN_FOOT_SEPARATION_M, not_across

# The weight is over a foot once the capture point is this far inside its sole's edges (a quarter of its width) [m]
WEIGHT_OVER_SOLE_M = FOOT_WIDTH_M / 4
# While the weight shifts for such a step, and back after it, each foot on the ground keeps at least this share of the
# weight: a foot with none is not a contact to the whole-body controller, and slides where its tasks move it [-]
REST_FOOT_MIN_WEIGHT = 0.05


def rest_step_plan(goals_xy: dict[str, np.ndarray], ankles_world: dict[str, np.ndarray],
                   heading_world: np.ndarray, min_m: float, reach_m: float) -> tuple[str, np.ndarray] | None:
    """The next step to where he stands: (the swinging foot, its landing (3,) world frame [m]), or None when no step
    brings a foot ``min_m`` nearer its place.

    ``goals_xy``: per foot, his foot's place on the character's path (2,) (world, horizontal) [m]; ``ankles_world``:
    both ankles (3,) [m]; ``heading_world``: (3, 3) the heading frame (x forward, y left), in which a landing across
    the other foot is moved outwards; ``reach_m``: the largest distance of the landing from where the foot is and from
    the other ankle [m]. Each foot's landing is its place, within those reaches and off the other foot (the places
    first spread to the feet's least separation sideways); the foot whose landing takes it the most nearer its place
    steps."""
    goals_xy = _side_by_side(goals_xy, heading_world)
    best: tuple[float, str, np.ndarray] | None = None
    for side in ("left", "right"):
        ankle = np.asarray(ankles_world[side], dtype=float)
        goal = np.asarray(goals_xy[side], dtype=float)[:2]
        landing = _landing(goal, ankle, np.asarray(ankles_world[OTHER_SIDE[side]], dtype=float), heading_world,
                           side, reach_m)
        gain = float(np.linalg.norm(goal - ankle[:2]) - np.linalg.norm(goal - landing[:2]))
        if best is None or gain > best[0]:
            best = (gain, side, landing)
    assert best is not None
    return (best[1], best[2]) if best[0] >= min_m else None


def _side_by_side(goals_xy: dict[str, np.ndarray], heading_world: np.ndarray) -> dict[str, np.ndarray]:
    """The feet's places moved apart sideways (in the heading frame), each by half of what they lack of
    MIN_FOOT_SEPARATION_M: his feet closer than that (a stance with the feet in line, or crossed) would each be a
    landing on the other foot."""
    left, right = (np.asarray(goals_xy[s], dtype=float)[:2] for s in ("left", "right"))
    y_axis = heading_world[:2, 1]
    lack = MIN_FOOT_SEPARATION_M - float((left - right) @ y_axis)
    if lack <= 0.0:
        return {"left": left, "right": right}
    return {"left": left + 0.5 * lack * y_axis, "right": right - 0.5 * lack * y_axis}


def _landing(goal_xy: np.ndarray, ankle_world: np.ndarray, stance_world: np.ndarray, heading_world: np.ndarray,
             side: str, reach_m: float) -> np.ndarray:
    """(3,) where the ankle of ``side`` lands on its way to ``goal_xy``: there, at most ``reach_m`` from where it is and
    from the other ankle ``stance_world``, and off that (outwards in the heading frame, then back within the reach
    along the heading)."""
    landing = ankle_world.copy()
    landing[:2] = ankle_world[:2] + _within(goal_xy - ankle_world[:2], reach_m)  # a step at most the reach long ...
    away = landing[:2] - stance_world[:2]  # ... and within the reach of the other foot
    dist = math.hypot(float(away[0]), float(away[1]))
    if dist > reach_m:
        landing[:2] = stance_world[:2] + away * (reach_m / dist)
    landing = not_across(landing, stance_world, heading_world, side)
    rel = heading_world.T @ np.array([landing[0] - stance_world[0], landing[1] - stance_world[1], 0.0])
    if math.hypot(float(rel[0]), float(rel[1])) > reach_m:
        rel[0] = math.copysign(math.sqrt(max(reach_m**2 - float(rel[1]) ** 2, 0.0)), float(rel[0]))
        landing[:2] = stance_world[:2] + (heading_world @ rel)[:2]
    return landing


def _within(vector_xy: np.ndarray, max_norm: float) -> np.ndarray:
    """``vector_xy`` shortened to at most ``max_norm`` long."""
    norm = math.hypot(float(vector_xy[0]), float(vector_xy[1]))
    return vector_xy * (max_norm / norm) if norm > max_norm else vector_xy

"""The operator's way over the ground: his COM's horizontal velocity averaged over longer than a step.

A walk's double stance and a sway from foot to foot on the spot look alike tick by tick: in both his COM moves along
the line through his feet (double_stance_momentum.moves_between_feet). Over a second they differ: the walker's COM
goes somewhere, the swaying dancer's comes back. The average of his (scaled) COM velocity with time constant ``T``,
``v̄ += (dt / T) (v - v̄)``, is his way over the ground; below ``min_speed_mps`` he is not going anywhere, and what
keeps a walking character's momentum (a double stance that does not brake it, its own steps that walk on) is not
applied (MotionConfig.gait_min_way_speed_mps).
"""

from __future__ import annotations

import numpy as np


class OperatorWay:
    """His COM's horizontal velocity [m/s], scaled onto the character, averaged with time constant ``time_s`` [s]."""

    def __init__(self, time_s: float, dt_s: float):
        self._share = min(dt_s / time_s, 1.0)
        self.velocity_world = np.zeros(2)  # the average (2,) [m/s]

    def prime(self, velocity_world: np.ndarray) -> None:
        """Start the average at ``velocity_world`` ((2,) or (3,), scaled) instead of rest [m/s]."""
        self.velocity_world = np.array(velocity_world, dtype=float)[:2]

    def update(self, velocity_world: np.ndarray) -> None:
        """Take one tick's scaled COM velocity ((2,) or (3,)) [m/s]."""
        v = np.asarray(velocity_world, dtype=float)[:2]
        self.velocity_world = self.velocity_world + self._share * (v - self.velocity_world)

    def goes(self, min_speed_mps: float | None, velocity_now_world: np.ndarray | None = None) -> bool:
        """Whether he goes somewhere: the average at least ``min_speed_mps`` fast (None: always) and, if given, his
        present scaled COM velocity ``velocity_now_world`` ((2,) or (3,)) too: the average trails a stop by its time
        constant, while his COM already stands over his feet [m/s]."""
        if min_speed_mps is None:
            return True
        if velocity_now_world is not None and float(np.hypot(*velocity_now_world[:2])) < min_speed_mps:
            return False
        return float(np.hypot(*self.velocity_world)) >= min_speed_mps

    def goes_along(self, min_speed_mps: float | None, velocity_now_world: np.ndarray, min_cos: float) -> bool:
        """Whether he goes somewhere (:meth:`goes`, with ``velocity_now_world``) and his present scaled COM velocity
        ((2,) or (3,) [m/s]) is within the angle whose cosine is ``min_cos`` of the average: a walk's, not the swing
        of a dance or a turn on the spot. False while the average is (nearly) zero."""
        if not self.goes(min_speed_mps, velocity_now_world):
            return False
        avg = self.velocity_world
        avg_speed = float(np.hypot(avg[0], avg[1]))
        if avg_speed < 1e-6:
            return False
        vx, vy = float(velocity_now_world[0]), float(velocity_now_world[1])
        return (avg[0] * vx + avg[1] * vy) / avg_speed >= min_cos * float(np.hypot(vx, vy))

    def direction_world(self) -> np.ndarray | None:
        """(3,) the unit horizontal direction of the average, or None when it is (nearly) zero."""
        speed = float(np.hypot(*self.velocity_world))
        if speed < 1e-6:
            return None
        return np.array([self.velocity_world[0] / speed, self.velocity_world[1] / speed, 0.0])

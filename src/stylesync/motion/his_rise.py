"""The operator's rise that a jump's push makes: his pelvis's upward speed, handed on only while he stands on both
feet and began the rise on them.

The whole-body controller tracks a share of the pelvis target's upward speed on both of the character's feet
(WholeBodyConfig.pelvis_rate_share; ``--no-track-rise``: none): a jump's push. Two other rises look alike tick by
tick:
- a run's stride: his pelvis rises from the middle of his stance on one foot into the flight, and in the flight his
  stance FSM (Sec. 5.1) passes through double stance for a sample or two as the rising foot passes the falling one at
  the same height; the character lands its foot there, and a push asked then works against its landing;
- a vault onto one foot (a kick's wind-up, a step): his pelvis rises as he lifts a foot, while the character may
  still stand on both.
A jump's push begins on both his feet (his pelvis turns upwards out of the crouch with both feet on the ground) and
lasts while they are: ``rise_mps`` is his pelvis's upward speed then, 0 otherwise (a descent is passed on as it is).
"""

from __future__ import annotations


class HisRise:
    """Latches whether his pelvis's present rise began while he stood on both feet."""

    def __init__(self) -> None:
        self._rising = False  # his pelvis went up at the last tick
        self._began_on_both_feet = False  # ... and that rise began in his double stance

    def rise_mps(self, his_pelvis_vel_z_mps: float, he_stands_on_both_feet: bool) -> float:
        """His pelvis's vertical speed (scaled) to hand on this tick [m/s]: as it is while it does not rise; while it
        rises, as it is if he stands on both feet and the rise began so, else 0."""
        rising = his_pelvis_vel_z_mps > 0.0
        if rising and not self._rising:
            self._began_on_both_feet = he_stands_on_both_feet
        self._rising = rising
        if not rising:
            self._began_on_both_feet = False
            return his_pelvis_vel_z_mps
        return his_pelvis_vel_z_mps if he_stands_on_both_feet and self._began_on_both_feet else 0.0

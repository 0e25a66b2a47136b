"""A lift-off that would leave the capture point beyond the stance sole, towards the lifted foot, waits however long
(MotionConfig.liftoff_behind_waits; docs/decisions.md, "A lift-off onto the wrong foot")."""

from __future__ import annotations

import dataclasses

import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig
from stylesync.model.character import LINK_NAMES
from stylesync.motion.recovery_step import beyond_sole_towards_m, capture_point
from stylesync.motion.stance_fsm import Stance, swing_side

_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
_OTHER = {"left": "right", "right": "left"}


def _run(waits: bool) -> tuple[float, bool, float | None]:
    """The humanoid3d run, seed 2: the largest distance of the capture point beyond the stance sole, towards the
    lifted foot, at a lift-off of a pressing foot (the rule's scope: a foot that bears weight) by the character,
    following the operator's from double stance [m]; whether it fell, and when."""
    worst = 0.0

    def watch(session):
        mass, g = session.mass, session.cfg.world.gravity_mps2
        last = [Stance.DS]

        def on_tick(state, ref) -> None:
            nonlocal worst
            stance, motion = ref.character_stance, session.motion
            lifted = swing_side(stance)
            if (last[0] is Stance.DS and lifted is not None and not motion.char_fsm.recovery_step
                    and state.feet_pressing()[lifted]):
                xi, _ = capture_point(mass.com(state), mass.com_velocity(state), g)
                other = _OTHER[lifted]
                worst = max(worst, beyond_sole_towards_m(xi, state.link_origin_world[_ANKLE[other]],
                                                         state.link_quat_wxyz[_ANKLE[other]],
                                                         state.link_origin_world[_ANKLE[lifted]]))
            last[0] = stance

        return on_tick

    # traced before the pelvis target came down as his swing went (swing_landing_within_reach)
    motion = dataclasses.replace(MotionConfig(), liftoff_behind_waits=waits, swing_landing_within_reach=False)
    result = suite_run("builtin:run", 2, motion, ControlConfig(), watch=watch)
    return worst, result.fell, result.fall_time_s


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_lift_off_onto_a_sole_the_capture_point_has_passed_waits():
    """The character stood on both feet, its right foot behind on its toes, while the operator, a stride ahead of it
    in his gait, stood on his right and lifted his left. The lift-off waited the weight shift's 0.25 s for the
    capture point to come back over the right sole, which no weight shift does when the body is moving past it; then
    it lifted the front foot, the only flat one, at 2.78 s, and the body fell at 3.02 s with both feet in the air
    (measured: the capture point 0.55 m beyond the right sole at that lift-off, the only one beyond 5 cm). Held down
    until the capture point is over that sole (the double stance's own rules step it meanwhile), the run goes on: on
    the processor it was traced on it completes (worst 0.046 m); on an AMD EPYC with AVX-512 (docs/decisions.md,
    "The development suite on another processor") it falls at 9.29 s, 3 s after an unweighted foot's lift-off (the
    rule's scope is a foot that bears weight), so the check is the traced fall's window."""
    worst, fell, fall_s = _run(False)
    assert fell and fall_s is not None and fall_s < 3.5 and worst > 0.15
    worst, fell, fall_s = _run(True)
    assert (not fell or (fall_s is not None and fall_s > 6.0)) and worst < 0.1  # measured: 0.046 m

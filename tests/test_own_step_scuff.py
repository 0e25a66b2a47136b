"""A step of the character's own whose foot touches the ground before its landing is due has scuffed it, not landed
(MotionConfig.own_step_scuff_before_due, opt-in; docs/decisions.md, "An own step's foot that scuffs the ground")."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig

WALK = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "05_01.bvh"


@pytest.mark.skipif(not WALK.is_file(), reason="../shared/mocap/cmu-dev/05_01.bvh is not present")
def test_a_scuffed_own_step_goes_on_to_its_landing():
    """Traced (CMU-dev 05_01, seed 8, the defaults of 2026-12-06): a swing taken over 0.03 s after his lift-off
    touched the ground 0.12 s after it, 0.55 m short of its landing, and ended there; the chain of steps of its own
    that followed ran the body to 2.4 m/s, and it fell at 4.65 s with the pelvis low. With the touch read as a scuff
    the step goes on to its landing and the run completes."""
    def run(motion: MotionConfig) -> tuple[bool, list[tuple[float, str]]]:
        begun: list[tuple[float, str]] = []  # each own step's start [s] and side
        last: list[object] = [None]

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is not None and step is not last[0]:
                    begun.append((state.time_s, step.side))
                last[0] = step
            return on_tick

        result = suite_run("bvh:" + str(WALK), 8, motion, ControlConfig(), watch=watch,
                           configure=lambda cfg: cfg.replace(duration_s=6.0))
        return result.fell, begun

    # (as traced: a taken-over swing lowered from where its foot is, wherever that is)
    fell_off, steps_off = run(MotionConfig(own_step_scuff_before_due=False, recovery_takeover_low_foot_m=None))
    fell_on, _ = run(MotionConfig(own_step_scuff_before_due=True, recovery_takeover_low_foot_m=None))
    assert fell_off and not fell_on
    # without it, the left foot's step taken over at 2.83 s ends within 0.1 s and the same foot steps again at once
    left = [t for t, side in steps_off if side == "left" and 2.8 < t < 3.0]
    assert len(left) == 2 and left[1] - left[0] < 0.15, steps_off

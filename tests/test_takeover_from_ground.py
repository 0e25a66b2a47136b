"""A swing taken over before its foot has left the ground is a step from the ground, not a foot in the air lowered
from where it is (MotionConfig.recovery_takeover_low_foot_m; docs/decisions.md, "A swing taken over on the
ground")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig
from stylesync.errors import ConfigError
from stylesync.model.character import ANKLE_HEIGHT_M
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M
from stylesync.motion.recovery_step import RecoveryStepper

G = 9.81
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
STANCE = np.array([0.0, -0.1, ANKLE_HEIGHT_M])  # the right foot on the ground
COM, VEL = np.array([0.15, -0.05, 0.82]), np.array([1.1, 0.0, 0.0])  # walking on over it
WALK = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "08_08.bvh"


def _heights(low_m: float | None, foot_up_m: float) -> tuple[bool, list[float]]:
    """Whether the step took the swing over as a foot in the air, and its target's height above the ground's ankle
    height [m] at each tenth of its swing, the foot taken over ``foot_up_m`` above it behind the stance foot."""
    stepper = RecoveryStepper(dataclasses.replace(MotionConfig(), recovery_takeover_low_foot_m=low_m),
                              CHAR_LEG_LENGTH_M, G)
    lifted = np.array([-0.35, 0.1, ANKLE_HEIGHT_M + foot_up_m])
    step = stepper.take_over("left", 1.0, lifted)
    heights = []
    for k in range(10):
        t = 1.0 + 0.1 * k * step.duration_s
        heights.append(float(stepper.swing_target(t, COM, VEL, STANCE, IDENTITY, np.eye(3))[2]) - ANKLE_HEIGHT_M)
    return step.lowered, heights


def test_a_swing_taken_over_on_the_ground_rises_a_step_height():
    step_height = MotionConfig().recovery_step_height_m
    # Lowered from where it is, a foot taken over on the ground has its target on the ground all the way: dragged.
    in_air, dragged = _heights(None, 0.001)
    assert in_air and max(dragged) < 0.002
    # Taken over below the step's height, it is a step from the ground: up by the step's height and down again.
    in_air, stepped = _heights(0.05, 0.001)
    assert not in_air
    assert max(stepped) == pytest.approx(step_height, abs=0.01) and stepped[0] < 0.005 and stepped[-1] < step_height
    # A foot up in the air (a kick's) is lowered from where it is, as before.
    assert _heights(0.05, 0.12) == _heights(None, 0.12)


def test_the_low_foot_height_is_not_negative():
    with pytest.raises(ConfigError, match="recovery_takeover_low_foot_m"):
        MotionConfig(recovery_takeover_low_foot_m=-0.01)


@pytest.mark.skipif(not WALK.is_file(), reason="../shared/mocap/cmu-dev/08_08.bvh is not present")
def test_a_fast_walk_stops_at_its_end_with_the_swing_taken_over_on_the_ground_stepped():
    """Traced (CMU-dev 08_08, seed 8, the defaults of 2026-12-06): in the rest after the clip, his held last frame,
    the balance took a swing over 0.01 s after his lift-off, its foot on the ground; lowered from there, the foot slid
    0.9 m along the ground, loaded, and came down beside the stance foot with the capture point 0.4 m beyond; the own
    steps after it ran the body to 2 m/s and it fell at 3.41 s. Stepped from the ground, the run completes."""
    def run(low_m: float | None) -> tuple[bool, list[float]]:
        lows: list[float] = []  # each taken-over swing's foot height at the take-over [m]

        def watch(session):
            stepper = session.motion.recovery
            take_over = stepper.take_over

            def recorded(side, time_s, ankle):
                lows.append(float(ankle[2]) - ANKLE_HEIGHT_M)
                return take_over(side, time_s, ankle)
            stepper.take_over = recorded
            return None

        result = suite_run("bvh:" + str(WALK), 8, MotionConfig(recovery_takeover_low_foot_m=low_m),
                           ControlConfig(), watch=watch)
        return result.fell, lows

    fell_off, lows_off = run(None)
    fell_on, _ = run(0.05)
    assert fell_off and not fell_on
    assert any(h < 0.005 for h in lows_off), lows_off  # a swing taken over with its foot on the ground

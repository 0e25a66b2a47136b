"""A swing taken over in the air keeps clear of the ground until its foot has come part of its way
(MotionConfig.recovery_takeover_clearance_share; docs/decisions.md, "A taken-over swing that comes down short")."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stylesync.config import MotionConfig
from stylesync.errors import ConfigError
from stylesync.model.character import ANKLE_HEIGHT_M
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M
from stylesync.motion.recovery_step import RecoveryStepper

G = 9.81
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
STANCE = np.array([0.0, -0.1, ANKLE_HEIGHT_M])  # the right foot on the ground
COM, VEL = np.array([0.15, -0.05, 0.82]), np.array([0.9, 0.0, 0.0])  # walking on over it
LIFTED = np.array([-0.35, 0.1, ANKLE_HEIGHT_M + 0.01])  # the left foot, taken over just after its lift-off


def _taken_over(share: float | None) -> RecoveryStepper:
    stepper = RecoveryStepper(dataclasses.replace(MotionConfig(), recovery_takeover_clearance_share=share),
                              CHAR_LEG_LENGTH_M, G)
    stepper.take_over("left", 1.0, LIFTED)
    return stepper


def _target(stepper: RecoveryStepper, t: float, ankle: np.ndarray) -> np.ndarray:
    return stepper.swing_target(t, COM, VEL, STANCE, IDENTITY, np.eye(3), None, ankle)


@pytest.mark.lowered_takeover
def test_a_taken_over_swing_that_trails_its_target_stays_up_until_its_foot_has_come_its_share_of_the_way():
    step_height = MotionConfig().recovery_step_height_m
    # Lowered along the target's travel (None), the target reaches the ground's height while the foot, trailing,
    # is still beside the stance foot.
    plain = _taken_over(None)
    beside = np.array([0.0, 0.1, ANKLE_HEIGHT_M + 0.01])
    late = _target(plain, 1.0 + 0.75 * plain.step.duration_s, beside)
    assert late[2] < ANKLE_HEIGHT_M + 0.004
    # With the clearance share the target stays a step's height up while the foot is short of its share of the way
    # ...
    held = _taken_over(0.5)
    late_held = _target(held, 1.0 + 0.75 * held.step.duration_s, beside)
    landing = held.step.landing_world
    gone = (beside[0] - LIFTED[0]) / (landing[0] - LIFTED[0])
    assert gone < 0.5 and landing[0] > COM[0]  # the landing is ahead of the body, the foot not halfway there
    assert late_held[2] == pytest.approx(ANKLE_HEIGHT_M + step_height)
    assert late_held[:2] == pytest.approx(late[:2])  # only the height differs
    # ... comes down as the foot goes on ...
    near = LIFTED + 0.8 * (landing - LIFTED)
    coming = _target(held, 1.0 + 0.75 * held.step.duration_s, near)
    assert ANKLE_HEIGHT_M < coming[2] < ANKLE_HEIGHT_M + step_height
    over = _target(held, 1.0 + 0.75 * held.step.duration_s, landing)
    assert over[2] == pytest.approx(late[2])  # over its landing: lowered along the target's travel, as without
    # ... and is aimed at the ground at the swing's end wherever the foot is (the step ends on time).
    end = _target(held, 1.0 + 1.01 * held.step.duration_s, beside)
    assert end[2] < ANKLE_HEIGHT_M


def test_the_clearance_share_is_a_share():
    with pytest.raises(ConfigError, match="recovery_takeover_clearance_share"):
        MotionConfig(recovery_takeover_clearance_share=1.0)

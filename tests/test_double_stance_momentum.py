import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig
from stylesync.metrics.summary import imitation_metrics
from stylesync.motion.double_stance_momentum import kept_com_velocity, moves_between_feet


def test_a_slower_character_keeps_its_speed_up_to_the_operators():
    his = np.array([1.0, 0.0])
    rate = np.array([0.1, 0.05, 0.0])
    # slower than him: its own speed along his direction, the sideways component kept
    np.testing.assert_allclose(kept_com_velocity(rate, his, np.array([0.6, -0.3, 0.0])), [0.6, 0.05, 0.0])
    # faster than him: his speed, no more
    np.testing.assert_allclose(kept_com_velocity(rate, his, np.array([1.5, 0.0, 0.0])), [1.0, 0.05, 0.0])
    # moving the other way, or a rate already above its speed: the rate as it was (never lowered)
    np.testing.assert_allclose(kept_com_velocity(rate, his, np.array([-0.2, 0.0, 0.0])), rate)
    fast_rate = np.array([1.2, 0.0, 0.0])
    np.testing.assert_allclose(kept_com_velocity(fast_rate, his, np.array([0.6, 0.0, 0.0])), fast_rate)
    # an operator standing still gives no direction
    np.testing.assert_allclose(kept_com_velocity(rate, np.zeros(2), np.array([0.6, 0.0, 0.0])), rate)


def test_along_an_oblique_walk_only_the_component_along_it_changes():
    his = np.array([0.6, 0.8])  # 1 m/s
    rate = np.array([0.0, 0.0, 0.0])
    out = kept_com_velocity(rate, his, np.array([0.3, 0.4, 0.0]))  # 0.5 m/s along his direction
    np.testing.assert_allclose(out, [0.3, 0.4, 0.0], atol=1e-12)


@pytest.mark.in_place
def test_the_built_in_walk_goes_further_along_the_operators_path_when_opted_in():
    """The built-in walk (seed 0, the development suite's run): without the kept momentum the double stances brake
    the character, which then covers less of its operator's way (0.39 measured); with it (0.1 m, the measured
    setting), no fall and a longer way (0.54)."""
    progress = {}
    for keep in (None, 0.1):
        result = suite_run("builtin:walk", 0, MotionConfig(double_stance_keeps_momentum_m=keep), ControlConfig())
        assert not result.fell, keep
        progress[keep] = imitation_metrics(result)["path_progress"]
    assert progress[0.1] > progress[None] + 0.08, progress


def test_a_gaits_double_stance_moves_from_one_foot_towards_the_other():
    left, right = np.array([0.3, 0.1, 0.05]), np.array([-0.3, -0.1, 0.05])  # a step along x
    assert moves_between_feet(np.array([1.0, 0.0, 0.0]), left, right)  # forward, onto the front foot
    assert moves_between_feet(np.array([-0.5, -0.2, 0.0]), left, right)  # backwards, either way
    assert not moves_between_feet(np.array([0.0, 1.0, 0.0]), left, right)  # across the feet: a sway
    # their line is at 18.4° to x: 40° off it is within, 50° off it beyond
    assert moves_between_feet(np.array([np.cos(np.radians(58.4)), np.sin(np.radians(58.4)), 0.0]), left, right)
    assert not moves_between_feet(np.array([np.cos(np.radians(68.4)), np.sin(np.radians(68.4)), 0.0]), left, right)
    assert not moves_between_feet(np.zeros(3), left, right)  # standing still

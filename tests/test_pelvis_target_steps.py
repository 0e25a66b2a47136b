"""The pelvis target does not step by decimetres within a control tick: Eq. 9 anchored on both of his feet measures
his pelvis from the ground under his feet, not from a foot he kicks into the air (MotionConfig.ds_anchor_ground_height),
and the lowering for a foot that must land comes down at a bounded speed (MotionConfig.landing_pelvis_descent_mps;
docs/decisions.md, "A foot on the ground that must land")."""

from __future__ import annotations

import dataclasses

import pytest
from conftest import TRACED_BEFORE_PRESS, suite_run

from stylesync.config import MotionConfig
from stylesync.errors import ConfigError

DESCENT_MPS = 2.0


def _largest_drop_m(**motion) -> float:
    """The humanoid3d spinning kick, sensor seed 0, by default but ``motion``, to 3.2 s: the largest fall of the
    pelvis target's height from one control tick to the next [m]."""
    last: list[float] = []
    drop = [0.0]

    def on_tick(state, ref) -> None:
        z = float(ref.pelvis_world[2])
        if last:
            drop[0] = max(drop[0], last[0] - z)
        last[:] = [z]

    def configure(cfg):  # traced without the pelvis target's floor (pelvis_min_height_m), which bounds the drop too,
        # before it came down as his swing went (swing_landing_within_reach) and before the targets' pull onto his path
        motion_cfg = dataclasses.replace(cfg.motion, **{"pelvis_min_height_m": None,
                                                        "swing_landing_within_reach": False,
                                                        "path_target_share": 0.0, **motion})
        return dataclasses.replace(cfg, motion=motion_cfg, duration_s=3.2)

    suite_run("builtin:spinkick", 0, MotionConfig(), TRACED_BEFORE_PRESS, on_tick=on_tick, configure=configure)
    return drop[0]


@pytest.mark.pelvis_joint
def test_his_kick_in_the_air_does_not_drop_the_pelvis_target_of_a_double_stance():
    # At 3.09 s the character stands on both feet while he kicks: from the mean of his ankles the target fell 0.67 m
    assert _largest_drop_m(ds_anchor_ground_height=False, landing_pelvis_descent_mps=None) > 0.6
    assert _largest_drop_m(ds_anchor_ground_height=True, landing_pelvis_descent_mps=None) < 0.45


@pytest.mark.in_place
def test_the_lowering_for_a_landing_foot_comes_down_at_a_bounded_speed():
    # Without the bound the lowering for a landing foot out of reach steps the target by 0.39 m (3.09 s)
    assert _largest_drop_m(ds_anchor_ground_height=True, landing_pelvis_descent_mps=None) > 0.3
    largest = _largest_drop_m(ds_anchor_ground_height=True, landing_pelvis_descent_mps=DESCENT_MPS)
    # his own pelvis's descent (Eq. 9) is not bounded: a few centimetres a tick at most in this clip
    assert largest < 0.1


def test_the_descent_bound_must_be_positive():
    with pytest.raises(ConfigError, match="landing_pelvis_descent_mps"):
        MotionConfig(landing_pelvis_descent_mps=0.0)

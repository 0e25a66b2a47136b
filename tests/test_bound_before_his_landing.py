"""While the operator is on one foot of his gait and the character on both (its step landed before his), the COM
target is bounded as in his gait's double stance, not within the soles (MotionConfig.capture_bound_before_his_landing;
docs/decisions.md, "A step landed before his")."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import TRACED_BEFORE_PRESS, suite_run

from stylesync.config import MotionConfig, follow_path
from stylesync.metrics.summary import imitation_metrics
from stylesync.motion.stance_fsm import Stance


def _followed_walk(bounded: bool) -> tuple[float, int, float, bool]:
    """The built-in walk, seed 0, 12 s, with ``--follow-path``: the mean desired COM speed over the ground while the
    character stands on both feet and the operator on one foot [m/s], how many control ticks that was, the share of
    his way the character went, and whether it fell."""
    speeds: list[float] = []

    def watch(session):
        def on_tick(state, ref) -> None:
            reading = session.reading
            if ref.character_stance is Stance.DS and reading.operator_stance is not Stance.DS:
                speeds.append(float(np.hypot(ref.com_vel_world[0], ref.com_vel_world[1])))

        return on_tick

    def configure(cfg):
        cfg = follow_path(cfg)
        # Traced before the rule for a foot lying on the ground (landing_reach_ground_gap_m), before the pelvis
        # target came down as his swing went (swing_landing_within_reach) and before the targets stood on the anchored
        # ones while he stands (reference_follows_standing_s): pinned off
        motion = dataclasses.replace(cfg.motion, capture_bound_before_his_landing=bounded,
                                     landing_reach_ground_gap_m=None, swing_landing_within_reach=False,
                                     reference_follows_standing_s=None)
        return dataclasses.replace(cfg, motion=motion)

    result = suite_run("builtin:walk", 0, MotionConfig(), TRACED_BEFORE_PRESS, watch=watch, configure=configure)
    progress = imitation_metrics(result)["path_progress"]
    return float(np.mean(speeds)), len(speeds), progress, result.fell


@pytest.mark.pelvis_joint
def test_a_step_landed_before_his_is_not_braked_to_a_stop():
    """Traced on the built-in walk with ``--follow-path`` (seed 0): the character's own steps land after 0.2 s
    against his 0.43 s swing, and on both feet, bounded within its soles, its COM target stood still while he walked
    on (from 0.84 to 0.60 m/s in 0.15 s before his landing at 7.27 s). Bounded as in his gait's double stance, the
    target goes on with him and the character goes further along his way (measured: 173 such control ticks, the
    target at rest in all of them, 0.79 of his way, without; 53 ticks, 0.60 m/s at the mean, 0.88 of it, with)."""
    speed_off, n_off, progress_off, fell_off = _followed_walk(True)
    speed_on, n_on, progress_on, fell_on = _followed_walk(False)
    assert not fell_off and not fell_on
    assert n_off > 20 and n_on > 20
    assert speed_off < 0.3 and speed_on > 0.5
    assert progress_on > progress_off + 0.05

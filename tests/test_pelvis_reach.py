"""The pelvis target (Eq. 9) within the reach of the planted stance legs (MotionConfig.pelvis_stance_reach_share)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import ConfigError, ControlConfig, MotionConfig, follow_path
from stylesync.model.character import ANKLE_HEIGHT_M
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M

WALK = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu" / "02_01.bvh"


def test_the_stance_reach_share_is_checked():
    assert MotionConfig(pelvis_stance_reach_share=None).pelvis_stance_reach_share is None
    for bad in (0.0, -0.5, 1.2):
        with pytest.raises(ConfigError):
            MotionConfig(pelvis_stance_reach_share=bad)


def _followed_walk(share: float | None) -> tuple[float, float, bool]:
    """CMU 02_01 (a walk at 1.2 m/s, his pelvis scaled above the character's straight legs), seed 0, with
    ``--follow-path``: the pelvis target's highest [m], the character's mean speed over the ground while he walks
    (0.5-2.8 s) [m/s], and whether it fell."""
    rec: list[tuple[float, float, float]] = []

    def on_tick(state, ref) -> None:
        rec.append((state.time_s, float(ref.pelvis_world[2]), float(np.hypot(*state.root_lin_vel_world[:2]))))

    def configure(cfg):
        cfg = follow_path(cfg)
        return dataclasses.replace(cfg, motion=dataclasses.replace(cfg.motion, pelvis_stance_reach_share=share,
                                                                             landing_reach_ground_gap_m=None))

    result = suite_run(f"bvh:{WALK}", 0, MotionConfig(), ControlConfig(), on_tick, configure=configure)
    a = np.array(rec)
    walking = (a[:, 0] > 0.5) & (a[:, 0] < 2.8)
    return float(a[:, 1].max()), float(a[walking, 2].mean()), result.fell


@pytest.mark.pelvis_joint
@pytest.mark.skipif(not WALK.exists(), reason="../shared/mocap/cmu/02_01.bvh is not available")
def test_a_pelvis_target_within_the_stance_legs_reach_lets_a_followed_walk_keep_its_pace():
    """Eq. 9 puts his pelvis, scaled, 6 cm above what the character's straight legs reach; the stance leg is held
    straight, and each late contact lowered the target by up to 11 cm in one tick for the landing foot to reach, which
    the stance knee took by folding: the walk lost 0.2 m/s at each of his landings (docs/decisions.md). Measured:
    0.78 m/s without the bound, 1.00 m/s with it (he walks at 1.15-1.25 m/s, scaled)."""
    high, speed, fell = _followed_walk(None)
    assert high > CHAR_LEG_LENGTH_M + 0.09 and speed < 0.85 and not fell
    high, speed, fell = _followed_walk(1.0)
    assert high <= CHAR_LEG_LENGTH_M + ANKLE_HEIGHT_M + 1e-9  # the leg's length above the ankle's height
    assert speed > 0.95 and not fell

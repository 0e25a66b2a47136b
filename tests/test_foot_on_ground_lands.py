"""A supporting foot that lies on the ground unpressed is not a foot that must land: the pelvis target is not lowered
for it (MotionConfig.landing_reach_ground_gap_m; docs/decisions.md, "A foot on the ground that must land")."""

from __future__ import annotations

import dataclasses

import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig, follow_path
from stylesync.model.character import LINK_NAMES
from stylesync.model.sole import sole_within_m

_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
DROP_M = 0.1  # a fall of the pelvis target within one control tick [m]
ON_GROUND_M = 0.003  # a sole whose lowest corner is this near the ground lies on it [m]


def _drops_for_resting_feet(gap_m: float | None) -> int:
    """The humanoid3d dance_a, sensor seed 15, with ``--follow-path``, to 6.75 s: the control ticks at which the
    pelvis target fell by more than DROP_M while a supporting foot lay on the ground without pressing it (where the
    trace of its fall began)."""
    drops = [0]
    last: list[float] = []

    def on_tick(state, ref) -> None:
        z = float(ref.pelvis_world[2])
        pressing = state.feet_pressing()
        resting = [s for s in _ANKLE if ref.stance_weight[s] > 0 and not pressing[s]
                   and sole_within_m(state.link_origin_world[_ANKLE[s]], state.link_quat_wxyz[_ANKLE[s]],
                                     ON_GROUND_M)]
        if last and last[0] - z > DROP_M and resting:
            drops[0] += 1
        last[:] = [z]

    def configure(cfg):
        cfg = follow_path(cfg)
        # (traced before the bound on the targets' lead and the targets on the anchored ones while he stands, off
        # here)
        motion = dataclasses.replace(cfg.motion, landing_reach_ground_gap_m=gap_m, reference_lead_max_m=None,
                                     reference_follows_standing_s=None)
        return dataclasses.replace(cfg, motion=motion, duration_s=6.75)

    suite_run("builtin:dance_a", 15, MotionConfig(), ControlConfig(), on_tick=on_tick, configure=configure)
    return drops[0]


@pytest.mark.pelvis_joint
def test_a_resting_foot_does_not_drop_the_pelvis_target():
    before = _drops_for_resting_feet(None)
    after = _drops_for_resting_feet(ON_GROUND_M)
    # Without the rule the target fell to its floor (0.3 m) and back on alternate ticks while the stance knee folded
    assert before >= 10, before
    assert after == 0, after

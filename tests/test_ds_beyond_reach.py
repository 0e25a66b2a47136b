"""A double stance whose capture point is already beyond a recovery step's reach steps at once
(MotionConfig.recovery_ds_beyond_reach; docs/decisions.md, "A double stance beyond a step's reach")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from conftest import TRACED_BEFORE_PRESS, suite_run

from stylesync.config import MotionConfig, follow_path
from stylesync.model.character import LINK_NAMES
from stylesync.motion.recovery_step import capture_point, soles_on_ground, support_outside_m
from stylesync.motion.stance_fsm import Stance

WALK = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "07_05.bvh"
_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
FAR_OUT_M = 0.3  # a capture point this far outside the soles is beyond any recovery step's reach [m]


def _followed_walk(beyond_reach: bool) -> tuple[float, bool, float | None]:
    """CMU-dev 07_05, seed 0, with ``--follow-path``: the longest time the character stood on both feet with its
    capture point more than FAR_OUT_M outside its soles [s], whether it fell, and when."""
    longest, since = 0.0, None

    def watch(session):
        mass, g = session.mass, session.cfg.world.gravity_mps2

        def on_tick(state, ref) -> None:
            nonlocal longest, since
            on_ground = soles_on_ground(state)
            xi, _ = capture_point(mass.com(state), mass.com_velocity(state), g)
            out = support_outside_m(xi, {s: state.link_origin_world[i] for s, i in _ANKLE.items()},
                                    {s: state.link_quat_wxyz[i] for s, i in _ANKLE.items()}, on_ground)
            if ref.character_stance is Stance.DS and len(on_ground) == 2 and out > FAR_OUT_M:
                since = state.time_s if since is None else since
                longest = max(longest, state.time_s - since)
            else:
                since = None

        return on_tick

    def configure(cfg):
        cfg = follow_path(cfg)
        # traced before the bound before his landing (docs/decisions.md, "A step landed before his"), off here
        motion = dataclasses.replace(cfg.motion, recovery_ds_beyond_reach=beyond_reach,
                                     capture_bound_before_his_landing=True,
                                     landing_reach_ground_gap_m=None)
        return dataclasses.replace(cfg, motion=motion)

    result = suite_run(f"bvh:{WALK}", 0, MotionConfig(), TRACED_BEFORE_PRESS, watch=watch, configure=configure)
    return longest, result.fell, result.fall_time_s


@pytest.mark.pelvis_joint
@pytest.mark.skipif(not WALK.exists(), reason="../shared/mocap/cmu-dev/07_05.bvh is not available")
def test_a_double_stance_beyond_a_steps_reach_steps_at_once():
    """A step of the character's own landed its right foot beside its left at 2.12 s while the body went on at
    1.1 m/s; its capture point was then 0.38 m outside the soles, already beyond a recovery step's reach, so the rule
    that steps a double stance before the operator's next lift-off did not step (no step would capture it), and the
    character waited on both feet for 0.44 s while the capture point ran 0.72 m out; it fell at 2.87 s. Stepping as
    far as a step reaches at once, the walk completes (measured: 0.44 s and the fall without the rule; 0.02 s with
    it)."""
    longest, fell, fall_s = _followed_walk(False)
    assert fell and fall_s is not None and fall_s < 3.0 and longest > 0.3
    longest, fell, _ = _followed_walk(True)
    assert not fell and longest < 0.1

"""The character's own steps walk on only as far as the operator's way goes forwards (MotionConfig.
recovery_walk_on_forward; docs/decisions.md, "Own steps that walk on sideways")."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import TRACED_BEFORE_PRESS, suite_run

from stylesync import rotations as rot
from stylesync.config import MotionConfig, follow_path


def _dance(forward: bool) -> tuple[bool, float | None, int, float]:
    """The humanoid3d dance_a, sensor seed 2, with ``--follow-path`` and ``recovery_walk_on_forward`` as given, to
    6.5 s: whether it fell, when, the control ticks of steps of its own taken while his way went more than 90°
    from his heading, and the pelvis's largest horizontal speed in those ticks [m/s]."""
    backwards = [0]
    speed = [0.0]

    def watch(session):
        motion = session.motion

        def on_tick(state, ref) -> None:
            way = motion.way.direction_world()
            yaw = rot.yaw_from_quat(ref.root_quat_wxyz)
            if motion.recovery.step is not None and way is not None and way[0] * np.cos(yaw) + way[1] * np.sin(yaw) < 0:
                backwards[0] += 1
                speed[0] = max(speed[0], float(np.hypot(*state.link_com_vel_world[0, :2])))
        return on_tick

    def configure(cfg):  # traced before the pelvis target came down as his swing went (swing_landing_within_reach)
        cfg = follow_path(cfg)  # ... before a backward way made his raised rear foot a stepping one, before the
        # targets stood on the anchored ones while he stands, and before his raised rear foot was read through a band
        motion = dataclasses.replace(cfg.motion, recovery_walk_on_forward=forward, swing_landing_within_reach=False,
                                     rear_foot_stepping_way_mps=None, reference_follows_standing_s=None,
                                     rear_foot_support_hysteresis_m=0.0)
        return dataclasses.replace(cfg, duration_s=6.5, motion=motion)

    result = suite_run("builtin:dance_a", 2, MotionConfig(), TRACED_BEFORE_PRESS, watch=watch, configure=configure)
    return result.fell, result.fall_time_s, backwards[0], speed[0]


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
def test_own_steps_do_not_walk_on_where_he_goes_sideways_or_backwards():
    fell, fall_s, backwards, speed = _dance(False)
    # His way 120-145° from his heading (he travels back and to the side, turning), the character's own steps landed
    # 0.1 m behind the capture point along it and the body ran on that way: traced, its COM reached 2.2 m/s and it
    # fell at 6.35 s; a trace this long is chaotic, and on another processor's floating point the run stood with its
    # pelvis at 3.0 m/s in those steps. Either way it ran away.
    assert backwards > 0 and (fell or speed > 2.5), (fell, fall_s, backwards, speed)
    fell, fall_s, _, speed_forward = _dance(True)
    assert not fell, fall_s
    assert speed_forward < 0.7 * speed, (speed_forward, speed)  # 1.7 against 3.0 m/s

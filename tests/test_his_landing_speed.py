"""His swing read as ending once the swing foot has stopped travelling (MotionConfig.his_landing_max_speed_mps;
docs/decisions.md, "His landing read while his foot still travels")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig, OperatorConfig, SessionConfig
from stylesync.errors import ConfigError
from stylesync.motion.stance_fsm import OperatorStanceFsm, Stance


def test_a_single_stance_lasts_while_the_swing_foot_still_travels():
    fsm = OperatorStanceFsm(0.04, 0.01)
    assert fsm.update(0.02, 0.10) is Stance.LS  # right foot up: he stands on the left
    # the heights say double stance (within 3 cm), the foot still travels: still his single stance
    assert fsm.update(0.02, 0.04, swing_moving=True) is Stance.LS
    assert fsm.update(0.02, 0.03, swing_moving=True) is Stance.LS
    assert fsm.update(0.02, 0.03, swing_moving=False) is Stance.DS
    # a lift-off is read from the heights alone
    assert fsm.update(0.10, 0.02, swing_moving=True) is Stance.RS


def test_the_speed_bound_must_be_positive():
    with pytest.raises(ConfigError, match="his_landing_max_speed_mps"):
        MotionConfig(his_landing_max_speed_mps=0.0)


def _his_landings(max_speed_mps: float | None) -> tuple[list[float], list[float]]:
    """His swing times [s] and his swing ankle's speed over the ground at each of his landings (scaled) [m/s], in
    the built-in walk from 2 to 8 s."""
    from stylesync.session import Session
    from stylesync.sources.builtin_operator import builtin_operator

    cfg = SessionConfig(duration_s=8.0, seed=0, operator=OperatorConfig(clip="walk"),
                        motion=dataclasses.replace(MotionConfig(), his_landing_max_speed_mps=max_speed_mps))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    rows: list[tuple[float, Stance, float, np.ndarray, np.ndarray]] = []
    update = session.motion.update

    def recorded(sample, *args, **kwargs):
        ref = update(sample, *args, **kwargs)
        reading = session.motion.reading
        rows.append((sample.time_s, reading.operator_stance, reading.scale,
                     sample.pos["ANKLE_LEFT"].copy(), sample.pos["ANKLE_RIGHT"].copy()))
        return ref

    session.motion.update = recorded
    session.run()
    swings, speeds, lift_s = [], [], None
    for k in range(1, len(rows) - 1):
        t, stance, scale = rows[k][0], rows[k][1], rows[k][2]
        before = rows[k - 1][1]
        if before is Stance.DS and stance is not Stance.DS:
            lift_s = t
        if before is not Stance.DS and stance is Stance.DS and t >= 2.0:
            side = 3 if before is Stance.RS else 4  # the swing foot: left while he stood on the right
            step = rows[k + 1][side][:2] - rows[k - 1][side][:2]
            speeds.append(scale * float(np.hypot(*step)) / (rows[k + 1][0] - rows[k - 1][0]))
            if lift_s is not None:
                swings.append(t - lift_s)
    return swings, speeds


def test_his_landings_come_when_his_foot_has_stopped():
    swings_heights, speeds_heights = _his_landings(None)
    swings, speeds = _his_landings(1.5)
    # By the heights alone his landing foot is still travelling at most of his landings (his heel rises as it comes
    # down); with the bound, it has slowed to about the bound at each, and his swings last longer.
    assert np.median(speeds_heights) > 1.5
    assert max(speeds) < 2.0 and np.median(speeds) < 1.5
    assert np.median(swings) > np.median(swings_heights) + 0.05


RUN = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "09_01.bvh"


@pytest.mark.unloaded_standing_sole
@pytest.mark.skipif(not RUN.exists(), reason="../shared/mocap/cmu-dev/09_01.bvh is not available")
def test_own_steps_walk_on_only_while_he_moves():
    """CMU-dev 09_01 (a 1.2 s run), seed 13, with his landings read at his foot's rest: he holds his last pose from
    1.2 s, and the character's own steps, walking on while his way's one-second average was still above the gait's
    speed, sped the body up from 0.5 to 1.5 m/s and it fell at 4.2 s (measured). Walking on only while he also moves
    now, it comes to rest."""
    def motion(now: bool) -> MotionConfig:
        return dataclasses.replace(MotionConfig(), his_landing_max_speed_mps=1.5,
                                   recovery_walk_on_needs_motion_now=now)

    result = suite_run(f"bvh:{RUN}", 13, motion(False), ControlConfig())
    assert result.fell and result.fall_time_s is not None and result.fall_time_s > 3.0
    assert not suite_run(f"bvh:{RUN}", 13, motion(True), ControlConfig()).fell

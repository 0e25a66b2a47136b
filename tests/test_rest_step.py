"""Steps to where the operator stands (motion/rest_step.py): which foot, where it lands, and when none is taken."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stylesync.config import ConfigError, MotionConfig
from stylesync.motion.recovery_step import MIN_FOOT_SEPARATION_M
from stylesync.motion.rest_step import rest_step_plan

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
HEADING = np.eye(3)  # x forward, y left
REACH_M = 0.35


def _feet(left_x: float, right_x: float, half_width_m: float = 0.1) -> dict[str, np.ndarray]:
    return {"left": np.array([left_x, half_width_m, 0.05]), "right": np.array([right_x, -half_width_m, 0.05])}


def _moved(feet: dict[str, np.ndarray], by_xy) -> dict[str, np.ndarray]:
    return {s: a[:2] + np.asarray(by_xy, dtype=float) for s, a in feet.items()}


def test_no_step_that_brings_a_foot_less_than_the_distance_nearer():
    feet = _feet(0.0, 0.0)
    assert rest_step_plan(_moved(feet, [0.06, -0.07]), feet, HEADING, 0.1, REACH_M) is None
    assert rest_step_plan(_moved(feet, [0.0, 0.11]), feet, HEADING, 0.1, REACH_M) is not None


def test_the_foot_behind_steps_past_the_other_to_its_place():
    """He stands 0.25 m ahead, feet as the character's: the right foot, 0.1 m behind the left, gets nearer its place
    than the left can (the left's landing is held within the reach of the right ankle)."""
    feet = _feet(0.1, 0.0)
    side, landing = rest_step_plan(_moved(feet, [0.25, 0.0]), feet, HEADING, 0.1, REACH_M)
    assert side == "right"
    assert landing == pytest.approx([0.25, -0.1, 0.05])
    # he stands behind: the left foot, ahead, steps back past the right
    side, landing = rest_step_plan(_moved(feet, [-0.25, 0.0]), feet, HEADING, 0.1, REACH_M)
    assert side == "left"
    assert landing == pytest.approx([-0.15, 0.1, 0.05])


def test_a_far_place_is_reached_over_several_steps_within_the_reach():
    feet = _feet(0.0, 0.0)
    goals = _moved(feet, [1.0, 0.0])
    sides = []
    for _ in range(10):
        plan = rest_step_plan(goals, feet, HEADING, 0.1, REACH_M)
        if plan is None:
            break
        side, landing = plan
        other = "left" if side == "right" else "right"
        assert np.hypot(*(landing - feet[other])[:2]) <= REACH_M + 1e-9
        feet[side] = landing
        sides.append(side)
    assert plan is None and len(sides) >= 4
    assert all(a != b for a, b in zip(sides, sides[1:], strict=False))  # the feet take turns, as in a walk
    for side in feet:
        assert np.linalg.norm(feet[side][:2] - goals[side]) < 0.1


def test_a_sideways_place_steps_the_foot_on_that_side_first():
    """He stands 0.3 m to the right: the left foot could not get nearer than the right one's side (it would land on
    it); the right foot steps out first, as far as the reach from the left allows, then the feet take turns."""
    feet = _feet(0.0, 0.0)
    goals = _moved(feet, [0.0, -0.3])
    side, landing = rest_step_plan(goals, feet, HEADING, 0.1, REACH_M)
    assert side == "right"
    assert landing == pytest.approx([0.0, 0.1 - REACH_M, 0.05])
    sides = []
    while (plan := rest_step_plan(goals, feet, HEADING, 0.1, REACH_M)) is not None and len(sides) < 10:
        feet[plan[0]] = plan[1]
        sides.append(plan[0])
    assert sides == ["right", "left", "right"]
    for side in feet:
        assert np.linalg.norm(feet[side][:2] - goals[side]) < 0.1


def test_a_landing_across_the_other_foot_is_moved_off_it():
    """His feet crossed (his left 0.3 m ahead and 0.05 m right of where the character's right foot stays): the left
    lands ahead of the right, outwards of it by the feet's least separation."""
    feet = _feet(0.0, 0.0)
    goals = {"left": np.array([0.3, -0.15]), "right": feet["right"][:2]}
    side, landing = rest_step_plan(goals, feet, HEADING, 0.1, REACH_M)
    assert side == "left"
    assert landing[1] == pytest.approx(-0.1 + MIN_FOOT_SEPARATION_M)
    assert 0.2 < landing[0] <= 0.3  # on its way ahead, no more than the reach from where it lifted off
    assert np.hypot(*(landing - feet["left"])[:2]) <= REACH_M + 1e-9


def test_on_by_default_off_in_place_and_validated():
    from stylesync.config import SessionConfig, in_place

    assert MotionConfig().rest_step_min_m == 0.1
    assert in_place(SessionConfig()).motion.rest_step_min_m is None
    with pytest.raises(ConfigError):
        MotionConfig(rest_step_after_s=-0.1)
    with pytest.raises(ConfigError):
        MotionConfig(rest_step_after_s=-0.1)
    for field in ("rest_step_shift_mps", "rest_step_swing_s", "rest_step_reach_m"):
        with pytest.raises(ConfigError):
            MotionConfig(**{field: 0.0})
    with pytest.raises(ConfigError):
        MotionConfig(rest_step_min_m=-0.1)


def _pushed_while_he_stands(rest_step_min_m: float | None, ball_mps: float = 14.0, seconds: float = 8.0):
    """The push experiment's standing pattern (he stands still; a football hits the character's chest at 2 s), seed 0:
    the run and the character's COM distance over the ground from where it stood before the push [m], at the end."""
    import dataclasses

    from stylesync.config import OperatorConfig, SessionConfig
    from stylesync.experiments import push
    from stylesync.session import Session
    from stylesync.sim.disturbance import throw_ball_at_chest
    from stylesync.sources.builtin_operator import sensed
    from stylesync.sources.human_model import HumanModel

    op = OperatorConfig(clip="push-stand")
    cfg = SessionConfig(duration_s=seconds, seed=0, operator=op)
    cfg = cfg.replace(motion=dataclasses.replace(cfg.motion, rest_step_min_m=rest_step_min_m, rest_step_after_s=0.5,
                                                 rest_step_shift_mps=2.0, rest_step_swing_s=0.4,
                                                 rest_step_reach_m=0.35))
    source = sensed(push.performer("stand", HumanModel(op.height_m, op.mass_kg)), op, cfg.clocks, seconds + 1.0, 0,
                    "push:stand")
    thrown: list[int] = []

    def hook(state, ref) -> None:
        if not thrown and state.time_s >= push.THROW_S:
            thrown.append(throw_ball_at_chest(session.backend, state, ball_mps, push.BALL_START_M))

    session = Session(cfg, source, on_tick=hook)
    result = session.run()
    lg = result.log
    before = int(np.searchsorted(lg.array("t"), push.THROW_S))
    x, y = lg.array("com_x"), lg.array("com_y")
    moved = np.hypot(x[-1] - x[before], y[-1] - y[before])
    return result, session, float(moved)


def test_a_character_pushed_off_its_place_while_he_stands_steps_back_to_it():
    """Traced: a 14 m/s ball moves the standing character back about 9 cm (its own recovery steps catch it); he has
    not moved. Without steps to where he stands it stays there; with them, one step brings it back within 1 cm."""
    stays, session, moved = _pushed_while_he_stands(None)
    assert not stays.fell and session.motion.rest_steps == 0
    assert moved > 0.07
    back, session, moved = _pushed_while_he_stands(0.1)
    assert not back.fell and session.motion.rest_steps >= 1
    assert moved < 0.02


def test_a_step_that_did_not_hold_is_not_taken_again_from_the_same_place(monkeypatch):
    """Traced: the humanoid3d punch (seed 0) ends about 0.5 m to the side of him, his weight over his right foot. The
    character's left foot steps out to his wide stance and, unloaded, slides back inwards; the same step was taken six
    times a second apart. Now no step repeats the last one from the same place to the same landing."""
    from stylesync.config import OperatorConfig, SessionConfig
    from stylesync.motion.recovery_step import RecoveryStepper
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    steps: list[tuple[str, np.ndarray, np.ndarray]] = []
    begin_to = RecoveryStepper.begin_to

    def recorded(self, side, time_s, lift_off_world, landing_world, duration_s):
        steps.append((side, np.array(lift_off_world[:2]), np.array(landing_world[:2])))
        return begin_to(self, side, time_s, lift_off_world, landing_world, duration_s)

    monkeypatch.setattr(RecoveryStepper, "begin_to", recorded)
    opened = open_source("builtin:punch", seed=0, duration_s=12.0)
    session = Session(SessionConfig(duration_s=12.0, seed=0, operator=OperatorConfig()), opened.source)
    result = session.run()
    opened.source.close()
    assert not result.fell and steps
    half = MotionConfig().rest_step_min_m / 2
    for (side_a, lift_a, land_a), (side_b, lift_b, land_b) in zip(steps, steps[1:], strict=False):
        assert not (side_a == side_b and np.linalg.norm(lift_a - lift_b) < half
                    and np.linalg.norm(land_a - land_b) < half)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_01.bvh is not available")
def test_a_walk_that_ends_ahead_of_the_character_is_closed_up_in_the_rest():
    """Traced: CMU-dev 08_01 (seed 0), a fast walk that ends at 2.27 s; the development suite's run (its 3 s rest)
    carried on to 9 s. Without steps to where he stands the character ends 0.75 m from him (its pelvis from his,
    scaled); with them 0.20 m."""
    import dataclasses

    from conftest import suite_run

    from stylesync.config import ControlConfig
    from stylesync.metrics import imitation as im

    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_01.bvh'}"

    def end_distance_m(rest_step_min_m):
        cfg = MotionConfig(rest_step_min_m=rest_step_min_m, rest_step_after_s=0.5, rest_step_shift_mps=2.0,
                           rest_step_swing_s=0.4, rest_step_reach_m=0.35)
        result = suite_run(spec, 0, cfg, ControlConfig(), configure=lambda c: dataclasses.replace(c, duration_s=9.0))
        assert not result.fell
        lg = result.log
        ch = lg.array("ch_joints")
        ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
        return float(np.linalg.norm((ch[-1, 0] - ref[-1, 0])[:2]))

    assert end_distance_m(None) > 0.65
    assert end_distance_m(0.1) < 0.3

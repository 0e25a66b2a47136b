"""The experiments' building blocks: scripted operator kinematics, the tuning ramp, the ball placement, the sync
experiment's sweeps."""

import numpy as np
import pytest

from stylesync.config import ControlConfig, JacobianTransposeConfig, MotionConfig, PidGains
from stylesync.experiments import kick, push, squat_jump, sync, tune
from stylesync.experiments.scripted_operator import pose_frame, sagittal_leg, standing_ankles
from stylesync.sources.deepmimic_clip import DeepMimicClip
from stylesync.sources.frame import JOINT_INDEX
from stylesync.sources.human_model import HumanModel


@pytest.mark.parametrize("target", [(0.0, -0.8), (-0.25, -0.78), (0.2, -0.7), (0.05, -0.6)])
def test_sagittal_leg_puts_the_ankle_on_target(target):
    human = HumanModel(1.75)
    leg = sagittal_leg(human, np.array(target))

    def down(angle):  # R_y(angle) applied to (0, 0, -1), in (x, z)
        return np.array([-np.sin(angle), -np.cos(angle)])

    ankle = human.thigh_m * down(leg["hip"]) + human.shank_m * down(leg["hip"] + leg["knee"])
    assert np.allclose(ankle, target, atol=1e-9)
    assert leg["knee"] >= 0.0  # a human knee flexes backward
    assert abs(leg["hip"] + leg["knee"] + leg["ankle"]) < 1e-12  # foot level


def test_push_step_moves_the_left_foot_back_and_lands_it():
    human = HumanModel(1.75)
    frame_at = push.performer("step", human)
    before, after = frame_at(push.THROW_S - 0.1), frame_at(push.THROW_S + 3 * push.STEP_S)
    i = JOINT_INDEX["ANKLE_LEFT"]
    assert after.joint_pos_world[i][0] == pytest.approx(before.joint_pos_world[i][0] - push.STEP_BACK_M, abs=1e-6)
    assert after.joint_pos_world[i][2] == pytest.approx(human.ankle_height_m, abs=1e-6)  # back on the floor
    mid = frame_at(push.THROW_S + 0.5 * push.STEP_S).joint_pos_world[i][2]
    assert mid > human.ankle_height_m + 0.5 * push.STEP_LIFT_M  # in the air half way


def test_squat_lowers_the_pelvis_with_feet_planted():
    human = HumanModel(1.75)
    frame_at = squat_jump.squat_performer(human)
    bottom = frame_at(squat_jump.SQUAT_START_S + squat_jump.SQUAT_DOWN_S + 0.5 * squat_jump.SQUAT_HOLD_S)
    top = frame_at(0.5)
    p = JOINT_INDEX["PELVIS"]
    drop = top.joint_pos_world[p][2] - bottom.joint_pos_world[p][2]
    assert drop == pytest.approx(squat_jump.SQUAT_DEPTH * (human.hip_height_m - 0.01), rel=1e-6)
    for side, ankle in standing_ankles(human).items():
        got = bottom.joint_pos_world[JOINT_INDEX[f"ANKLE_{side.upper()}"]]
        assert np.allclose(got[[0, 2]], ankle[[0, 2]], atol=1e-6)


def test_a_pelvis_shifted_sideways_rolls_the_legs_and_keeps_the_feet_planted_and_level():
    human = HumanModel(1.75)
    ankles = standing_ankles(human)
    for shift in (0.0, 0.09, -0.05):
        frame = pose_frame(human, 0.0, np.array([0.0, shift, human.hip_height_m - 0.02]), ankles)
        for side, ankle in ankles.items():
            S = side.upper()
            got = frame.joint_pos_world[JOINT_INDEX[f"ANKLE_{S}"]]
            assert np.allclose(got, ankle, atol=2e-4)  # the knee stops 1e-6 short of straight
            toe = frame.joint_pos_world[JOINT_INDEX[f"FOOT_{S}"]]
            assert toe[1] == pytest.approx(got[1], abs=1e-9)  # the foot points forward ...
            assert toe[2] == pytest.approx(frame.joint_pos_world[JOINT_INDEX["FOOT_LEFT"]][2], abs=1e-9)  # level


def test_the_scripted_kick_shifts_the_weight_then_strikes_forward_and_comes_back():
    human = HumanModel(1.75)
    frame_at = kick.kick_performer(human)
    a, p = JOINT_INDEX["ANKLE_RIGHT"], JOINT_INDEX["PELVIS"]
    lift = kick.KICK_START_S + kick.SHIFT_S
    stand, shifted = frame_at(0.5), frame_at(lift)
    assert shifted.joint_pos_world[p][1] - stand.joint_pos_world[p][1] == pytest.approx(kick.SHIFT_M, abs=1e-9)
    assert np.allclose(shifted.joint_pos_world[a], stand.joint_pos_world[a], atol=2e-4)  # not lifted yet
    struck = frame_at(lift + kick.DRAW_S + kick.STRIKE_S).joint_pos_world[a] - stand.joint_pos_world[a]
    assert struck[0] == pytest.approx(kick.STRIKE_AHEAD_M, abs=2e-4)
    assert struck[2] == pytest.approx(kick.STRIKE_UP_M, abs=2e-4)
    end = frame_at(lift + kick.DRAW_S + kick.STRIKE_S + kick.RETURN_S + kick.SHIFT_S)
    assert np.allclose(end.joint_pos_world[a], stand.joint_pos_world[a], atol=2e-4)
    assert np.allclose(end.joint_pos_world[p], stand.joint_pos_world[p], atol=1e-9)
    # the ball: in front of his toe at the strike, scaled to the character: clear of his standing toe (and so of
    # the smaller character's), in line with the right foot
    ball = kick.ball_position(frame_at, human, 0.0, kick.KICK_START_S + kick.KICK_AFTER_S, "FOOT_RIGHT")
    toe0 = stand.joint_pos_world[JOINT_INDEX["FOOT_RIGHT"]]
    assert ball[0] - kick.BALL_RADIUS_M > toe0[0] + 0.05
    assert abs(ball[1] - toe0[1]) < 0.02
    assert ball[2] == kick.BALL_RADIUS_M


def test_tuning_ramp_error_falls_with_stiffer_gains():
    clip = DeepMimicClip.builtin("walk")
    slope, height, axis = tune.ramp_spec(clip, "knee")
    assert 1.0 < slope < 20.0 and 0.5 < height < 2.0  # a walking knee: a few rad/s, about a radian
    base = JacobianTransposeConfig().pid["knee"]
    soft = tune.ramp_error("knee", PidGains(base.kp / 4, 0.0, base.kd / 4), slope, height, axis)
    stiff = tune.ramp_error("knee", PidGains(base.kp * 2, 0.0, base.kd * 2), slope, height, axis)
    assert stiff[0] < soft[0]
    assert stiff[1] < np.radians(5.0)


def test_the_kick_claim_needs_the_walk_to_reach_the_ball_and_the_kick_to_move_it():
    walk = {"reached": True, "kicked": False, "fell": False}
    kicked = {"reached": True, "kicked": True, "fell": False}
    assert kick.claim_holds({"walk-to-ball": walk, "kick": kicked})  # the walk need not push the ball
    assert not kick.claim_holds({"walk-to-ball": {**walk, "reached": False}, "kick": kicked})
    assert not kick.claim_holds({"walk-to-ball": walk, "kick": {**kicked, "kicked": False}})
    assert not kick.claim_holds({"walk-to-ball": {**walk, "fell": True}, "kick": kicked})
    assert not kick.claim_holds({"walk-to-ball": walk, "kick": {**kicked, "fell": True}})


@pytest.mark.in_place
def test_a_free_swing_carries_the_kicks_strike_to_the_ball():
    """The scripted kick from standing, seed 1 (`stylesync experiment kick`'s "kick"): with the free swing, the
    swing foot follows his relative to the stance foot while both stand balanced on it, strikes forward and moves
    the ball, with no fall. Without it the swing goes from its lift-off to its landing, which for a kick in place
    is where it lifted off: the foot only rises and comes down, and never reaches the ball."""
    reach = {}
    for free in (False, True):
        _, m, _ = kick.run_one("kick", 1, MotionConfig(free_swing=free), ControlConfig())
        reach[free] = m
    assert not reach[True]["fell"] and reach[True]["kicked"]
    assert reach[True]["closest_foot_m"] < 0.1
    assert not reach[False]["kicked"] and reach[False]["closest_foot_m"] > 0.25


@pytest.mark.unloaded_standing_sole
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_kick_does_not_lift_off_with_the_weight_already_beyond_the_stance_ankle():
    """The scripted kick with the free swing, seed 0: lifting off with its capture point 2.4 cm outside its stance
    ankle (and moving out), the character could not bring it back; the strike pushed it out of the sole, the swing
    went back to a landing and missed the ball. Waiting until it is within 1 cm of the ankle outwards as well
    (``liftoff_shift_outward_m``), the foot strikes and moves the ball, with no fall."""
    out = {}
    for outward in (None, 0.01):
        _, m, _ = kick.run_one("kick", 0, MotionConfig(free_swing=True, liftoff_shift_outward_m=outward),
                               ControlConfig())
        out[outward] = m
    assert not out[None]["kicked"] and out[None]["closest_foot_m"] > 0.25
    assert out[0.01]["kicked"] and not out[0.01]["fell"]


@pytest.mark.unloaded_standing_sole
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_stance_foot_off_the_ground_is_held_where_it_came_off():
    """The scripted kick, seed 14: while the weight shifts onto the left foot the right one bears no force and comes
    a few millimetres off the ground. Pressed down only, it slid 0.2 m forwards and inwards (the QP swung the free leg
    for momentum), the lift-off came from there with the weight never over the stance sole, and the kick missed.
    Held where it came off (WholeBodyConfig.press_holds_foot, off by default and in --free-swing), it stays within
    3 cm and the kick moves the ball."""
    from stylesync.config import FREE_SWING_MOTION, MotionConfig, WholeBodyConfig

    out = {}
    for hold in (False, True):
        # traced before a double stance's unweighted foot was pressed down (press_double_stance_feet)
        control = ControlConfig(whole_body=WholeBodyConfig(press_holds_foot=hold, press_double_stance_feet=False))
        # (its MotionConfig made here, under the test's markers: kick.FREE_SWING is made at import)
        result, m, _ = kick.run_one("kick", 14, motion=MotionConfig(**FREE_SWING_MOTION), control=control)
        t = result.log.array("t")
        shift = (t > kick.KICK_START_S) & (t < kick.KICK_START_S + kick.SHIFT_S + 0.25)  # before any lift-off
        right = np.stack([result.log.array("ar_x"), result.log.array("ar_y")], axis=1)[shift]
        out[hold] = (float(np.linalg.norm(right - right[0], axis=1).max()), m)
    assert out[False][0] > 0.1 and not out[False][1]["kicked"]
    assert out[True][0] < 0.03 and out[True][1]["kicked"] and not out[True][1]["fell"]


def test_the_sync_sensor_rate_sweep_runs_each_rate_both_ways_and_finds_where_the_term_decides(monkeypatch):
    """The sweep's runs (fake: the walk without the term falls at 6 Hz and below on seeds but the last, with it
    never): every rate of SENSOR_RATES_HZ at the operator's own speed, with and without the term, on SWEEP_SEEDS seeds
    from the run's; the term decides where no run with it falls and most without it do."""
    calls = []

    def fake_walk(lipm, speed, duration_s, seed, sensor_hz=None):
        calls.append((lipm, speed, seed, sensor_hz))
        return {"fell": (not lipm) and sensor_hz <= 6.0 and seed < 10 + sync.SWEEP_SEEDS - 1, "fall_time_s": None,
                "state_transition_delay_s": {"max": 0.1}}

    monkeypatch.setattr(sync, "_walk", fake_walk)
    monkeypatch.setattr(sync, "summarize", lambda m: m)
    rows = sync.sensor_rate_sweep(12.0, 10)
    assert [r["sensor_hz"] for r in rows] == list(sync.SENSOR_RATES_HZ)
    assert sorted(calls) == sorted((lipm, 1.0, 10 + k, hz) for hz in sync.SENSOR_RATES_HZ for lipm in (True, False)
                                   for k in range(sync.SWEEP_SEEDS))
    assert [x["seed"] for x in rows[0]["without"]] == [10 + k for k in range(sync.SWEEP_SEEDS)]
    assert sync.deciding_settings(rows, "sensor_hz") == [hz for hz in sync.SENSOR_RATES_HZ if hz <= 6.0]

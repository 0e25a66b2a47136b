"""The experiments' building blocks: scripted operator kinematics, the tuning ramp, the ball placement."""

import numpy as np
import pytest

from stylesync.config import JacobianTransposeConfig, PidGains
from stylesync.experiments import kick, push, squat_jump, tune
from stylesync.experiments.scripted_operator import sagittal_leg, standing_ankles
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

"""His pelvis at his hip joints (MotionConfig.pelvis_from_hip_joints) and the pelvis target's offset below his
(MotionConfig.pelvis_height_offset_m): the retargeting of Eq. 9-10 does not depend on where a skeleton puts its
pelvis joint, and a CMU walk's pelvis target comes within the reach of the character's legs."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import PELVIS_JOINT_MOTION, ControlConfig, MotionConfig, SessionConfig
from stylesync.errors import ConfigError
from stylesync.model.character import LINK_NAMES, OPERATOR_JOINTS
from stylesync.motion.initial_state import retargeted_pose
from stylesync.motion.operator_analysis import analyse_operator
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M, pelvis_offset_m
from stylesync.processing.body_parameters import hip_centre_world, paired_operator_joints
from stylesync.processing.operator_processing import OperatorProcessing
from stylesync.sources.frame import JOINT_INDEX
from stylesync.sources.registry import open_source

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
_ANKLES = [LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")]


def _sample(frame):
    processing = OperatorProcessing(SessionConfig().clocks, SessionConfig().filters)
    processing.push(frame)
    return processing.step(frame.timestamp_s)


def test_the_hip_centre_is_the_midpoint_of_the_hip_joints():
    pos = {"HIP_LEFT": np.array([0.1, 0.2, 0.9]), "HIP_RIGHT": np.array([0.3, -0.2, 0.7]),
           "PELVIS": np.array([5.0, 5.0, 5.0])}
    assert hip_centre_world(pos) == pytest.approx([0.2, 0.0, 0.8])


def test_the_metrics_compare_the_characters_root_with_his_hip_centre():
    # The imitation metrics' joint 0 is where the character's root is on its body, whatever joint his skeleton
    # calls its pelvis: a CMU-like Hips root 0.1 m above the hips changes no paired joint.
    frame = open_source("deepmimic:walk", sensor="none", seed=0).source.frames[40]
    pos = {n: frame.pos(n).copy() for n in OPERATOR_JOINTS}
    raised = dict(pos, PELVIS=pos["PELVIS"] + np.array([0.03, 0.0, 0.10]))
    a, b = paired_operator_joints(pos, OPERATOR_JOINTS), paired_operator_joints(raised, OPERATOR_JOINTS)
    assert np.array_equal(a, b)
    assert a[OPERATOR_JOINTS.index("PELVIS")] == pytest.approx(hip_centre_world(pos))
    assert a[OPERATOR_JOINTS.index("NECK")] == pytest.approx(pos["NECK"])


def test_the_retargeted_pose_does_not_depend_on_where_the_skeleton_puts_its_pelvis_joint():
    frame = open_source("deepmimic:walk", sensor="none", seed=0).source.frames[40]
    raised = dataclasses.replace(frame, joint_pos_world=frame.joint_pos_world.copy())
    raised.joint_pos_world[JOINT_INDEX["PELVIS"]] += np.array([0.03, 0.0, 0.10])  # a CMU-like Hips root
    s, r = _sample(frame), _sample(raised)
    for a, b in zip(retargeted_pose(s, analyse_operator(s), from_hip_joints=True),
                    retargeted_pose(r, analyse_operator(r), from_hip_joints=True), strict=True):
        assert np.allclose(a, b, atol=1e-9)
    # Taken from the pelvis joint (the default), the root goes up with it (scaled by h_C / h_H, Eq. 9)
    assert retargeted_pose(r, analyse_operator(r))[0][2] - retargeted_pose(s, analyse_operator(s))[0][2] > 0.08


def test_the_pelvis_target_is_offset_below_his_as_he_goes_somewhere():
    assert pelvis_offset_m(-0.07, 0.0, 0.5) == 0.0  # standing still
    assert pelvis_offset_m(-0.07, 0.25, 0.5) == pytest.approx(-0.035)
    assert pelvis_offset_m(-0.07, 1.6, 0.5) == pytest.approx(-0.07)
    assert pelvis_offset_m(-0.07, 0.9, 1.5, 1.0) == 0.0  # below a start speed, none
    assert pelvis_offset_m(-0.07, 1.25, 1.5, 1.0) == pytest.approx(-0.035)
    with pytest.raises(ConfigError, match="pelvis_offset_full_speed_mps"):
        MotionConfig(pelvis_offset_full_speed_mps=0.0)
    with pytest.raises(ConfigError, match="pelvis_offset_full_speed_mps"):
        MotionConfig(pelvis_offset_start_speed_mps=1.0, pelvis_offset_full_speed_mps=0.8)


@pytest.mark.skipif(not (MOCAP / "cmu" / "02_01.bvh").is_file(), reason="../shared/mocap/cmu/02_01.bvh is not present")
def test_a_cmu_walks_pelvis_target_comes_within_the_legs_reach():
    """CMU's BVH files root their skeleton at a ``Hips`` joint 0.1 m above the hip joints. Taken as his pelvis, the
    pelvis target of CMU 02_01 (seed 0, its first 2 s) lay above the lower ankle by more than the character's
    straight leg at the median (measured 0.857 m against 0.831 m): its stance leg could not bend, and its steps were
    0.42-0.47 m against his 0.5-0.8 m (docs/decisions.md, "His pelvis at his hip joints"). From his hip joints and
    lowered as he goes (the default) it is below the straight leg by more than the offset."""
    def median_height(motion: MotionConfig) -> float:
        heights = []

        def on_tick(state, ref):
            if state.time_s <= 2.0:
                ankle_z = min(float(state.link_origin_world[k, 2]) for k in _ANKLES)
                heights.append(float(ref.pelvis_world[2]) - ankle_z)

        suite_run("bvh:" + str(MOCAP / "cmu" / "02_01.bvh"), 0, motion, ControlConfig(), on_tick=on_tick,
                  configure=lambda cfg: cfg.replace(duration_s=2.0))
        return float(np.median(heights))

    assert median_height(MotionConfig(**PELVIS_JOINT_MOTION)) > CHAR_LEG_LENGTH_M  # `--pelvis-joint`
    assert median_height(MotionConfig()) < CHAR_LEG_LENGTH_M - 0.07


def test_the_lowered_pelvis_leaves_his_swing_foot_height():
    """His swing foot's height above his ground is his style (Sec. 5.2): the pelvis target lowered by
    default does not lower the swing foot's target with it. Measured on the DeepMimic walk (seed 0, 4 s), the swing
    ankle's height at the 90th percentile of the character's single stances (its own steps left out): 0.258 m with
    `--pelvis-joint`, 0.264 m by default; 0.202 m with the swing target lowered with the pelvis."""
    from stylesync.motion.stance_fsm import Stance

    def swing_height_m(motion: MotionConfig) -> float:
        heights = []

        def on_tick(state, ref):
            if ref.character_stance is not Stance.DS and ref.recovery_ankle_world is None:
                swing = _ANKLES[1] if ref.character_stance is Stance.LS else _ANKLES[0]
                heights.append(float(state.link_origin_world[swing, 2]))

        suite_run("deepmimic:walk", 0, motion, ControlConfig(), on_tick=on_tick,
                  configure=lambda cfg: cfg.replace(duration_s=4.0))
        return float(np.percentile(heights, 90))

    assert swing_height_m(MotionConfig()) > swing_height_m(MotionConfig(**PELVIS_JOINT_MOTION)) - 0.02


def test_pelvis_joint_on_the_command_line_sets_both():
    import argparse

    from stylesync.cli import _motion_options

    names = ("in_place", "follow_path", "free_swing", "late_contact_steps", "no_track_rise", "damp_angular_momentum")
    args = argparse.Namespace(**dict.fromkeys(names, False), pelvis_joint=True)
    motion = _motion_options(SessionConfig(), args).motion
    assert not motion.pelvis_from_hip_joints and motion.pelvis_height_offset_m == 0.0
    default = _motion_options(SessionConfig(), argparse.Namespace(**dict.fromkeys(names, False), pelvis_joint=False))
    assert default.motion.pelvis_from_hip_joints and default.motion.pelvis_height_offset_m == -0.07

"""A recorded clip starts the character in the clip's own state; its end holds the last pose on both feet; leading
bind-pose frames of converted BVH files are left out."""

from pathlib import Path

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.config import OperatorConfig, SessionConfig
from stylesync.model.character import ANKLE_HEIGHT_M, JOINTS, LINK_NAMES, JointKind
from stylesync.motion.initial_state import initial_state, retargeted_pose
from stylesync.motion.operator_analysis import analyse_operator
from stylesync.processing.operator_processing import OperatorProcessing
from stylesync.session import Session
from stylesync.sim.pybullet_backend import PyBulletBackend
from stylesync.sources.bvh import bind_blend_frames
from stylesync.sources.frame import JOINT_INDEX
from stylesync.sources.registry import FEET_DOWN_S, open_source

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
needs_cmu_dev = pytest.mark.skipif(not (MOCAP / "cmu-dev").is_dir(),
                                   reason="../shared/mocap/cmu-dev (Poser/DAZ CMU clips) is not present")


def _sample(frame):
    processing = OperatorProcessing(SessionConfig().clocks, SessionConfig().filters)
    processing.push(frame)
    return processing.step(frame.timestamp_s)


def test_initial_velocities_are_the_motion_between_the_two_poses():
    frames = open_source("deepmimic:walk", sensor="none", seed=0).source.frames
    s0, s1 = _sample(frames[40]), _sample(frames[46])
    dt = s1.time_s - s0.time_s
    init = initial_state(s0, analyse_operator(s0), s1, analyse_operator(s1))
    _, _, j1 = retargeted_pose(s1, analyse_operator(s1))
    for k, j in enumerate(JOINTS):  # integrating the velocities over dt gives the second pose
        if j.kind is JointKind.BALL:
            q = rot.multiply(init.joint_pos[k], rot.quat_from_rotvec(init.joint_vel[k] * dt))
            assert abs(float(q @ j1[k])) == pytest.approx(1.0, abs=1e-9), j.name
        else:
            assert init.joint_pos[k, 0] + init.joint_vel[k, 0] * dt == pytest.approx(j1[k, 0], abs=1e-9), j.name
    # The engine reads the velocities as meant: one physics step moves each joint by velocity x step.
    backend = PyBulletBackend(SessionConfig().world, 600.0)
    backend.reset(init.root_pos_world + np.array([0.0, 0.0, 1.0]), init.root_quat_wxyz, init.joint_pos)  # in the air
    backend.set_velocities(init.root_lin_vel_world, init.root_ang_vel_world, init.joint_vel)
    backend.step()
    q = backend.read_state(0.0).joint_pos
    for k, j in enumerate(JOINTS):
        if j.kind is JointKind.BALL:
            q_k = rot.align_sign(q[k], init.joint_pos[k])
            moved = rot.rotvec_from_quat(rot.multiply(rot.conjugate(init.joint_pos[k]), q_k))
        else:
            moved = np.array([q[k, 0] - init.joint_pos[k, 0], 0.0, 0.0])
        expected = init.joint_vel[k] / 600.0
        assert np.linalg.norm(moved - expected) < 0.1 * np.linalg.norm(expected) + 1e-5, j.name
    backend.close()


@pytest.mark.pelvis_joint
@needs_cmu_dev
def test_a_bvh_run_starts_in_the_first_frame_pose_on_the_ground():
    op = OperatorConfig()
    opened = open_source(f"bvh:{MOCAP / 'cmu-dev' / '07_05.bvh'}", seed=0, operator=op)
    first = opened.source.frames[0]
    assert first.timestamp_s < 0.0 <= opened.source.frames[1].timestamp_s  # both frames due at the start
    session = Session(SessionConfig(duration_s=0.1, operator=op), opened.source)
    session._place_character()
    state = session.backend.read_state(0.0)
    assert np.allclose(state.root_pos_world[:2], first.pos("PELVIS")[:2], atol=1e-9)
    ankles_z = [state.link_origin_world[LINK_NAMES.index(f"{s}_ankle"), 2] for s in ("left", "right")]
    assert min(ankles_z) == pytest.approx(ANKLE_HEIGHT_M + 0.002, abs=1e-6)
    # Mid-stride: the operator's feet are apart and so are the character's (not the standing pose).
    op_gap = np.linalg.norm(first.pos("ANKLE_LEFT")[:2] - first.pos("ANKLE_RIGHT")[:2])
    ch_gap = np.linalg.norm(np.subtract(*[state.link_origin_world[LINK_NAMES.index(f"{s}_ankle"), :2]
                                          for s in ("left", "right")]))
    assert op_gap > 0.2 and 0.6 * op_gap < ch_gap < 1.05 * op_gap  # scaled by h_C / h_H (Eq. 9)
    session.backend.close()


@needs_cmu_dev
def test_the_held_last_pose_stands_on_both_feet():
    op = OperatorConfig()
    opened = open_source(f"bvh:{MOCAP / 'cmu-dev' / '08_01.bvh'}", seed=0, operator=op, sensor="none")
    performer = opened.performer
    clip_end = performer.performer.duration_s
    end = performer.frame_at(clip_end)
    rest = performer.frame_at(clip_end + FEET_DOWN_S + 0.5)
    z_end = [end.pos(f"ANKLE_{s}")[2] for s in ("LEFT", "RIGHT")]
    z_rest = [rest.pos(f"ANKLE_{s}")[2] for s in ("LEFT", "RIGHT")]
    assert abs(z_end[0] - z_end[1]) > 0.03  # the clip ends with a foot raised
    assert z_rest[0] == pytest.approx(z_rest[1], abs=1e-9) == pytest.approx(min(z_end), abs=1e-9)
    assert np.allclose(rest.pos("PELVIS"), end.pos("PELVIS"))
    assert opened.duration_s == pytest.approx(clip_end + op.rest_after_clip_s)


def test_bind_pose_blend_frames_are_found():
    t = np.arange(240) / 120.0
    pos = np.zeros((240, 32, 3))
    pos[:, JOINT_INDEX["WRIST_LEFT"], 0] = 0.3 * np.sin(2 * np.pi * t)  # a hand waving at about 1.9 m/s at most
    assert bind_blend_frames(pos, 1 / 120) == 0
    pos[:4, JOINT_INDEX["WRIST_LEFT"], 2] = [0.8, 0.6, 0.35, 0.1]  # frames blending from an arms-up bind pose
    assert bind_blend_frames(pos, 1 / 120) == 4


def test_the_start_speed_share():
    from stylesync.motion.initial_state import start_velocity_share

    assert start_velocity_share(np.array([3.0, 4.0, 1.0]), None) == 1.0
    assert start_velocity_share(np.array([3.0, 4.0, 9.0]), 2.5) == pytest.approx(0.5)  # horizontal speed 5 m/s
    assert start_velocity_share(np.array([0.3, 0.4, 0.0]), 1.0) == 1.0  # slower than the bound: as it is
    assert start_velocity_share(np.zeros(3), 0.0) == 1.0


@needs_cmu_dev
@pytest.mark.parametrize("max_mps", [None, 1.0])
def test_a_clip_started_at_its_speed_no_faster_than_the_bound(max_mps):
    """CMU-dev 08_07 starts at 2.3 m/s (scaled): started with its velocities its root moves that fast; with the bound,
    at the bound, its joints slowed by the same share."""
    from stylesync.errors import ConfigError

    op = OperatorConfig(start_with_clip_velocity=True, start_speed_max_mps=max_mps)
    opened = open_source(f"bvh:{MOCAP / 'cmu-dev' / '08_07.bvh'}", seed=0, operator=op)
    session = Session(SessionConfig(duration_s=0.1, operator=op), opened.source)
    session._place_character()
    state = session.backend.read_state(0.0)
    speed = float(np.hypot(*state.root_lin_vel_world[:2]))
    if max_mps is None:
        assert speed > 2.0
    else:
        assert speed == pytest.approx(max_mps, abs=1e-6)
    session.backend.close()
    with pytest.raises(ConfigError, match="start_speed_max_mps"):
        OperatorConfig(start_speed_max_mps=-1.0)

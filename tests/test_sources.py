import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stylesync.errors import SourceError
from stylesync.sources.deepmimic_clip import DeepMimicClip


@given(st.text(max_size=200))
@settings(max_examples=50, deadline=None)
def test_clip_parser_rejects_garbage_cleanly(tmp_path_factory, text):
    p = tmp_path_factory.mktemp("c") / "clip.txt"
    p.write_text(text)
    try:
        DeepMimicClip.load(p)
    except SourceError:
        pass


def test_clip_with_nan_rejected(tmp_path):
    frame = [0.03] + [0.0] * 43
    frame[8] = float("nan")
    p = tmp_path / "c.txt"
    p.write_text(json.dumps({"Loop": "none", "Frames": [frame, frame]}).replace("NaN", "NaN"))
    with pytest.raises(SourceError):
        DeepMimicClip.load(p)


def test_builtin_walk_loads_and_loops():
    clip = DeepMimicClip.builtin("walk")
    a, b = clip.pose_at(0.2), clip.pose_at(0.2 + clip.duration_s)
    assert np.linalg.norm((b.root_pos_world - a.root_pos_world)[:2]) > 0.5


def test_builtin_walk_starts_from_standing_and_reaches_the_clip_speed():
    """The looping walk starts from standing: no pelvis jump at the end of the lead-in, a speed that grows over the
    start ramp, and after it the clip's own pelvis velocity."""
    from stylesync.config import ClockConfig, OperatorConfig
    from stylesync.sources.builtin_operator import builtin_operator
    from stylesync.sources.frame import JOINT_INDEX

    op = OperatorConfig()
    _, performer = builtin_operator(op, ClockConfig(), 1.0, 0)
    pelvis = JOINT_INDEX["PELVIS"]

    def pos(t):
        return performer.frame_at(t).joint_pos_world[pelvis]

    def speed(t):
        return float(np.linalg.norm((pos(t + 0.01) - pos(t))[:2]) / 0.01)

    start = op.standing_lead_in_s
    assert np.linalg.norm(pos(start - 0.01) - pos(start + 0.01)) < 1e-3
    assert speed(start + 0.05) < 0.1 < speed(start + 0.6) < speed(start + op.start_ramp_s + 0.5)
    clip = performer.clip
    t_after = start + op.start_ramp_s + 0.5
    clip_v = (clip.pose_at(t_after - start + 0.01).root_pos_world - clip.pose_at(t_after - start).root_pos_world)
    v_clip = float(np.linalg.norm(clip_v[:2]) / 0.01) * performer.leg_ratio
    assert speed(t_after) == pytest.approx(v_clip, rel=1e-6)


def _ankles_and_heading(performer, times):
    """His ankles (T, 2, 3) [m] and pelvis heading (T,) [rad] at ``times`` [s]."""
    from stylesync import rotations as rot

    frames = [performer.frame_at(t) for t in times]
    ankles = np.array([[f.pos("ANKLE_LEFT"), f.pos("ANKLE_RIGHT")] for f in frames])
    heading = np.unwrap([rot.yaw_from_quat(f.quat("PELVIS")) for f in frames])
    return ankles, heading


def _down_foot_slide_m(ankles, up_m=0.03):
    """The farthest an ankle moves over the ground [m] while it stays within ``up_m`` of its lowest height."""
    low = ankles[:, :, 2].min(axis=0)
    worst = 0.0
    for k in range(ankles.shape[1]):
        start = None
        for i in range(len(ankles)):
            if ankles[i, k, 2] - low[k] >= up_m:
                start = None
                continue
            start = i if start is None else start
            worst = max(worst, float(np.linalg.norm(ankles[i, k, :2] - ankles[start, k, :2])))
    return worst


def test_the_rate_ramp_starts_a_loop_from_its_own_pose_with_no_foot_sliding():
    """``OperatorConfig.start_ramp="rate"``: the walk starts in the clip's pose with both feet down, the clip's time
    grows as u_0 + τ² / (2 T), and a foot on the ground moves no more than in the clip played at its own pace (the
    heel-to-toe roll); the blend slides the walk's left foot 0.1 m further than that at a few centimetres' height."""
    from stylesync.config import ClockConfig, OperatorConfig
    from stylesync.sources.builtin_operator import ClipPerformer, builtin_operator
    from stylesync.sources.human_model import HumanModel

    times = np.arange(0.0, 3.5, 1.0 / 60.0)
    op = OperatorConfig()
    own = ClipPerformer(DeepMimicClip.builtin("walk"), HumanModel(op.height_m, op.mass_kg))
    clip_slide = _down_foot_slide_m(_ankles_and_heading(own, times)[0])
    slides = {}
    for ramp in ("rate", "blend"):
        op = OperatorConfig(start_ramp=ramp)
        _, performer = builtin_operator(op, ClockConfig(), 1.0, 0)
        ankles, _ = _ankles_and_heading(performer, times)
        slides[ramp] = _down_foot_slide_m(ankles)
        if ramp == "rate":
            assert performer.rate_ramp
            assert (ankles[0, :, 2] - ankles[:, :, 2].min(axis=0)).max() <= 0.05  # he stands on both feet
            ramp_s, u0 = op.start_ramp_s, performer.start_phase_s
            assert performer.clip_time_s(0.5) == u0
            assert performer.clip_time_s(1.0 + 0.5 * ramp_s) == pytest.approx(u0 + ramp_s / 8)
            assert performer.clip_time_s(1.0 + 2.0 * ramp_s) == pytest.approx(u0 + 1.5 * ramp_s)
    assert slides["rate"] <= clip_slide + 0.01
    assert slides["blend"] > clip_slide + 0.1


def test_the_rate_ramp_turns_a_turning_clip_along_its_own_path():
    """The blend turns the dancer the shorter way about his heading in one frame; the rate ramp turns him no faster
    than the clip itself does; a run, whose feet are never both down, is blended in with either setting."""
    from stylesync import rotations as rot
    from stylesync.config import ClockConfig, OperatorConfig
    from stylesync.sources.builtin_operator import builtin_operator

    times = np.arange(0.0, 4.0, 1.0 / 120.0)
    clip = DeepMimicClip.builtin("dance_a")
    clip_yaw = np.unwrap([rot.yaw_from_quat(clip.pose_at(t).local_quats["PELVIS"]) for t in times])
    clip_step = float(np.abs(np.diff(clip_yaw)).max())
    turns = {}
    for ramp in ("rate", "blend"):
        _, performer = builtin_operator(OperatorConfig(clip="dance_a", start_ramp=ramp), ClockConfig(), 1.0, 0)
        _, heading = _ankles_and_heading(performer, times)
        turns[ramp] = float(np.abs(np.diff(heading)).max())
    assert turns["rate"] <= clip_step + 1e-9
    assert turns["blend"] > np.radians(90.0)
    _, run = builtin_operator(OperatorConfig(clip="run", start_ramp="rate"), ClockConfig(), 1.0, 0)
    assert not run.rate_ramp


def test_an_unknown_start_ramp_is_a_clear_configuration_error():
    from stylesync.config import OperatorConfig
    from stylesync.errors import ConfigError

    with pytest.raises(ConfigError, match="start_ramp"):
        OperatorConfig(start_ramp="jump")


def test_a_faster_operator_plays_the_clip_faster_after_the_lead_in():
    """``OperatorConfig.playback_speed``: the same lead-in, then the clip's time runs that many times faster (the
    sync experiment's speed sweep); a speed of zero or less is a clear configuration error."""
    from stylesync.config import ClockConfig, OperatorConfig
    from stylesync.errors import ConfigError
    from stylesync.sources.builtin_operator import builtin_operator

    op = OperatorConfig()
    _, normal = builtin_operator(op, ClockConfig(), 1.0, 0)
    _, fast = builtin_operator(OperatorConfig(playback_speed=1.5), ClockConfig(), 1.0, 0)
    lead = op.standing_lead_in_s
    for t in (0.3, lead):
        assert np.array_equal(fast.frame_at(t).joint_pos_world, normal.frame_at(t).joint_pos_world)
    for u in (0.4, 1.7, 3.2):  # clip time after the lead-in, within and past the start ramp
        f, n = fast.frame_at(lead + u / 1.5), normal.frame_at(lead + u)
        assert np.allclose(f.joint_pos_world, n.joint_pos_world, atol=1e-9)
        assert f.timestamp_s == pytest.approx(lead + u / 1.5)
    with pytest.raises(ConfigError, match="playback_speed"):
        OperatorConfig(playback_speed=0.0)


@pytest.mark.parametrize("value, says", [("1e300", "NaN or infinite"), ("1e308", "NaN or infinite"),
                                         ("1e7", "limit 1000 m"), ("nan", "NaN or infinite")])
def test_bvh_positions_and_rotations_out_of_this_world_are_one_clear_error(tmp_path, value, says):
    """Positions of 1e300 or 1e308 once became Infinity and NaN in metrics.json, and a NaN rotation silently an
    identity; a root 100 km from where the recording starts is no human motion either."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fuzz"))
    from targets import _bvh_seed

    from stylesync.errors import SourceError
    from stylesync.sources.registry import open_source

    lines = _bvh_seed().decode().splitlines()
    row = lines.index("MOTION") + 4  # the second frame
    values = lines[row].split()
    values[0 if value != "nan" else 4] = value  # root x position, or a root rotation
    lines[row] = " ".join(values)
    path = tmp_path / "clip.bvh"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(SourceError, match=says):
        open_source(f"bvh:{path}", duration_s=1.0)


def test_a_looping_clip_costs_work_in_its_cycles_not_their_square(monkeypatch):
    """A looping clip's root travel over n cycles is Σ_{k<n} R_z(k·yaw) offset (each cycle's offset turned by the
    heading gained before it), and asking for the pose at every frame of a long run builds each cycle's rotation
    once: opening a looping clip used to take time quadratic in the run's length."""
    from stylesync import rotations as rot
    from stylesync.sources import deepmimic_clip

    def frame(x_m: float, yaw_rad: float) -> list[float]:
        f = [0.001, x_m, 0.9, 0.0, float(np.cos(yaw_rad / 2)), 0.0, float(np.sin(yaw_rad / 2)), 0.0]
        for _, kind, _width in deepmimic_clip._CLIP_LAYOUT:
            f += [1.0, 0.0, 0.0, 0.0] if kind == "ball" else [0.0]
        return f

    clip = DeepMimicClip(np.array([frame(0.0, 0.0), frame(0.01, np.radians(1.0))]), loop=True)
    calls = {"n": 0}
    real = rot.quat_from_yaw

    def counted(yaw: float) -> np.ndarray:
        calls["n"] += 1
        return real(yaw)

    monkeypatch.setattr(rot, "quat_from_yaw", counted)
    times = np.arange(0.0, 2.0, 0.0005)  # 4000 poses over 2000 cycles
    poses = [clip.pose_at(float(t)) for t in times]
    # each pose builds its own heading once; the travel's rotations are built once per cycle (2000), not per pose
    # and cycle (about 4 million)
    assert calls["n"] <= 2 * len(times) + 2000 + 1
    n = 1500
    z = np.exp(1j * clip.cycle_yaw)
    travel = complex(*clip.cycle_offset[:2]) * (1 - z ** n) / (1 - z)
    start = clip.root_pos[0] * np.array([1.0, 1.0, 0.0])
    pose = clip.pose_at(n * clip.duration_s)
    expected = start + np.array([travel.real, travel.imag, 0.0]) + rot.matrix_from_quat(
        real(n * clip.cycle_yaw)) @ (clip.root_pos[0] - start)
    assert np.allclose(pose.root_pos_world, expected, atol=1e-9)
    assert np.linalg.norm(poses[-1].root_pos_world - poses[0].root_pos_world) > 0.5


def _straight_walker(speed_mps: float):
    """A pose function: the pelvis at 0.9 m going along +x at ``speed_mps``, the left ankle 0.1 m to its left and
    0.2 m ahead, every segment facing +x."""
    from stylesync import rotations as rot
    from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame

    def pose_at(t_s: float) -> OperatorFrame:
        pos = np.zeros((N_JOINTS, 3))
        pos[:] = [speed_mps * t_s, 0.0, 0.9]
        pos[JOINT_INDEX["ANKLE_LEFT"]] = [speed_mps * t_s + 0.2, 0.1, 0.05]
        quats = np.tile(rot.IDENTITY_WXYZ, (N_JOINTS, 1))
        return OperatorFrame(t_s, pos, quats, np.ones(N_JOINTS), com_world=pos[JOINT_INDEX["PELVIS"]].copy())
    return pose_at


def test_turning_path_bends_a_straight_walk_into_a_circle_at_its_own_speed():
    from stylesync import rotations as rot
    from stylesync.sources.frame import JOINT_INDEX
    from stylesync.sources.turning_path import TurningPath

    speed, rate, start = 1.0, 0.5, 1.0
    straight = _straight_walker(speed)
    bent = TurningPath(straight, rate, start_s=start, end_s=start + 2 * np.pi / rate + 0.5)
    assert bent(0.5) is not None and np.array_equal(bent(0.5).joint_pos_world, straight(0.5).joint_pos_world)
    pelvis, ankle = JOINT_INDEX["PELVIS"], JOINT_INDEX["ANKLE_LEFT"]
    for t in (2.0, 4.5, 9.0):
        f, g = bent(t), bent(t + 0.01)
        step = g.joint_pos_world[pelvis, :2] - f.joint_pos_world[pelvis, :2]
        theta = rate * (t - start)
        # his speed over the ground as recorded, his way turned by the heading
        assert np.linalg.norm(step) / 0.01 == pytest.approx(speed, rel=1e-3)
        assert np.degrees(np.arctan2(step[1], step[0])) == pytest.approx(
            np.degrees((theta + np.pi) % (2 * np.pi) - np.pi), abs=0.5)
        # the body turned about the vertical with him: the ankle's offset and every segment's orientation
        offset = f.joint_pos_world[ankle] - f.joint_pos_world[pelvis]
        assert offset == pytest.approx([0.2 * np.cos(theta) - 0.1 * np.sin(theta),
                                        0.2 * np.sin(theta) + 0.1 * np.cos(theta), 0.05 - 0.9], abs=1e-9)
        assert f.quat("PELVIS") == pytest.approx(rot.quat_from_yaw(theta), abs=1e-9)
        assert f.com_world == pytest.approx(f.joint_pos_world[pelvis], abs=1e-9)
    # a full turn closes a circle of radius speed / rate
    a, b = bent(start).joint_pos_world[pelvis], bent(start + 2 * np.pi / rate).joint_pos_world[pelvis]
    assert np.linalg.norm(b[:2] - a[:2]) < 0.02
    half = bent(start + np.pi / rate).joint_pos_world[pelvis]
    assert np.linalg.norm(half[:2] - a[:2]) == pytest.approx(2 * speed / rate, rel=0.01)


def test_a_turn_rate_that_is_not_finite_is_refused():
    from stylesync.config import OperatorConfig
    from stylesync.errors import ConfigError

    with pytest.raises(ConfigError, match="turn_rate_rad_s"):
        OperatorConfig(turn_rate_rad_s=float("nan"))

"""Session files, replay and BVH export."""

import json

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.config import SessionConfig
from stylesync.errors import SourceError
from stylesync.export.bvh_export import bvh_local_quats
from stylesync.export.replay import export_bvh
from stylesync.export.session_file import SessionRecorder, read_session
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cfg = SessionConfig(duration_s=1.5)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, 2.5, 0)
    session = Session(cfg, source)
    path = tmp_path_factory.mktemp("s") / "run.jsonl"
    rec = SessionRecorder(path, cfg, session)
    states = []

    def tick(state, ref):
        rec.tick(state, ref)
        states.append(state)

    session.on_tick = tick
    result = session.run()
    rec.close({"fell": result.fell})
    return path, states


def test_a_deferred_session_file_has_the_same_lines(recorded, tmp_path):
    # Written when the run ends instead of tick by tick: the same file (the run is deterministic).
    path, _ = recorded
    cfg = SessionConfig(duration_s=1.5)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, 2.5, 0)
    session = Session(cfg, source)
    rec = SessionRecorder(tmp_path / "deferred.jsonl", cfg, session, deferred=True)
    session.on_tick = rec.tick
    result = session.run()
    assert (tmp_path / "deferred.jsonl").read_text().count("\n") == 1  # only the header until the end
    rec.close({"fell": result.fell})
    assert (tmp_path / "deferred.jsonl").read_bytes() == path.read_bytes()


def test_session_file_replays_identical_states(recorded):
    path, states = recorded
    s = read_session(path)
    assert s.metrics == {"fell": False} and len(s.ticks) == len(states) > 150
    for tk, st in zip(s.ticks, states, strict=True):
        assert tk["t"] == st.time_s
        assert np.array_equal(np.array(tk["root_pos_world"]), st.root_pos_world)
        assert np.array_equal(np.array(tk["joint_pos"]), st.joint_pos)
        assert np.array_equal(np.array(tk["link_quat_wxyz"]), st.link_quat_wxyz)
    assert len(s.ticks[-1]["torques_nm"]) == 12 and s.ticks[-1]["operator_stance"] in ("LS", "DS", "RS")


def test_truncated_session_file_keeps_its_complete_ticks(recorded, tmp_path):
    path, _ = recorded
    text = path.read_text()
    cut = tmp_path / "cut.jsonl"
    cut.write_text(text[: len(text) // 2])
    s = read_session(cut)
    assert s.metrics is None and 10 < len(s.ticks) < len(read_session(path).ticks)
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps({"format": "other"}) + "\n")
    with pytest.raises(SourceError, match="not a stylesync session"):
        read_session(bad)


def test_bvh_export_reimports_with_the_same_joint_angles(recorded, tmp_path):
    import bvhio

    path, _ = recorded
    s = read_session(path)
    out = tmp_path / "char.bvh"
    n = export_bvh(s, out, fps=60.0)
    container = bvhio.readAsBvh(str(out))
    assert container.FrameCount == n
    # Frame Time is the export clock's period, whatever the gaps of the recorded ticks; the file lasts the session.
    header = next(line for line in out.read_text().splitlines() if line.startswith("Frame Time:"))
    frame_time = float(header.split()[-1])
    assert frame_time == pytest.approx(1 / 60, abs=1e-8)
    t_rec = s.array("t")
    assert (n - 1) * frame_time == pytest.approx(t_rec[-1] - t_rec[0], abs=1 / 60)
    # the motion at the 60 Hz clock, interpolated between the two recorded ticks around each time
    t = s.array("t")
    grid = np.arange(t[0], t[-1] + 1e-9, 1 / 60)
    links, roots = [], []
    for g in grid:
        hi = min(max(int(np.searchsorted(t, g)), 1), len(t) - 1)
        w = (g - t[hi - 1]) / (t[hi] - t[hi - 1])
        a, b = s.ticks[hi - 1], s.ticks[hi]
        links.append([rot.slerp(np.array(qa), np.array(qb), w) for qa, qb in zip(a["link_quat_wxyz"],
                                                                                  b["link_quat_wxyz"], strict=True)])
        roots.append((1 - w) * np.array(a["root_pos_world"]) + w * np.array(b["root_pos_world"]))
    expected = bvh_local_quats(np.array(links))
    joints = {}
    stack = [container.Root]
    while stack:
        j = stack.pop()
        joints[j.Name] = j
        stack.extend(j.Children)
    worst = 0.0
    for name, q_exp in expected.items():
        got = np.array([[k.Rotation.w, k.Rotation.x, k.Rotation.y, k.Rotation.z] for k in joints[name].Keyframes])
        d = rot.batch_rotvec(rot.batch_multiply(rot.batch_conjugate(q_exp), got))
        worst = max(worst, float(np.max(np.linalg.norm(d, axis=1))))
    assert worst < 1e-3
    # root translation in centimetres, Y up
    root = np.array([[k.Position.x, k.Position.y, k.Position.z] for k in joints["root"].Keyframes])
    assert root[:, 1] == pytest.approx(100 * np.array(roots)[:, 2], abs=1e-3)
    # between recorded ticks, not on them: the clocks differ
    assert np.min(np.abs(grid[1:, None] - t[None, :]), axis=1).max() > 1e-3


def _end_sites(text: str) -> dict[str, np.ndarray]:
    """BVH text -> the End Site offset under each joint [cm, BVH axes]."""
    ends, joint, lines = {}, None, text.splitlines()
    for k, line in enumerate(lines):
        words = line.split()
        if words[:1] in (["ROOT"], ["JOINT"]):
            joint = words[1]
        if words[:2] == ["End", "Site"]:
            ends[joint] = np.array([float(v) for v in lines[k + 2].split()[1:4]])
    return ends


def test_bvh_end_sites_are_the_character_segment_ends(recorded, tmp_path):
    """The hands', toes' and head's end sites carry the character's segment ends, not zero-length points: the
    top of the head at the character's height (1.62 m), the toes ahead of the ankles at the sole, the hands'
    tips beyond the wrists along the forearms."""
    from stylesync.export.replay import rest_link_origins
    from stylesync.model.character import LINK_NAMES

    path, _ = recorded
    out = tmp_path / "char.bvh"
    export_bvh(read_session(path), out, fps=60.0)
    ends = _end_sites(out.read_text())
    rest = rest_link_origins()
    idx = {n: i for i, n in enumerate(LINK_NAMES)}
    # BVH axes: X left, Y up, Z forward, centimetres
    assert rest[idx["neck"], 2] + ends["neck"][1] / 100 == pytest.approx(1.62, abs=0.01)
    for side in ("left", "right"):
        toe = ends[f"{side}_ankle"]
        assert toe[2] > 10.0 and toe[1] == pytest.approx(-100 * rest[idx[f"{side}_ankle"], 2], abs=1.0)
        forearm = 100 * (rest[idx[f"{side}_wrist"]] - rest[idx[f"{side}_elbow"]])
        hand = ends[f"{side}_elbow"]
        assert np.linalg.norm(hand) > np.linalg.norm(forearm) + 2.0  # the hand's tip beyond the wrist


_BLENDER_SCRIPT = """
import json, sys
import bpy, addon_utils
bpy.ops.wm.read_factory_settings(use_empty=True)
addon_utils.enable("io_anim_bvh", default_set=True)
bpy.ops.import_anim.bvh(filepath=sys.argv[1], global_scale=0.01, frame_start=1, use_fps_scale=False,
                        update_scene_fps=True, rotate_mode="NATIVE")
scene = bpy.context.scene
arm = next(o for o in scene.objects if o.type == "ARMATURE")
print("RESULT " + json.dumps({"fps": scene.render.fps / scene.render.fps_base,
                              "frame_range": list(arm.animation_data.action.frame_range),
                              "bones": {b.name: b.length for b in arm.data.bones}}))
"""


def test_blender_imports_the_bvh_at_the_session_speed_with_the_character_bones(recorded, tmp_path):
    """Blender's own BVH importer (bpy, an optional test dependency: ``pip install bpy``) reads the export at 60
    fps, with one keyframe per exported frame (the file lasts the session), and bones as long as the character's
    segments, the end segments to their tips."""
    import importlib.util
    import subprocess
    import sys

    if importlib.util.find_spec("bpy") is None:
        pytest.skip("bpy (Blender as a Python module) is not installed: pip install bpy")
    from stylesync.export.replay import rest_link_origins, segment_ends_rest
    from stylesync.model.character import LINK_NAMES

    path, _ = recorded
    s = read_session(path)
    out = tmp_path / "char.bvh"
    n = export_bvh(s, out, fps=60.0)
    script = tmp_path / "import.py"
    script.write_text(_BLENDER_SCRIPT)
    proc = subprocess.run([sys.executable, str(script), str(out)], capture_output=True, text=True, timeout=300)
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")), None)
    assert line is not None, proc.stderr[-2000:]
    got = json.loads(line[len("RESULT "):])
    assert got["fps"] == pytest.approx(60.0, rel=1e-5)
    first, last = got["frame_range"]
    assert last - first + 1 == n
    t = s.array("t")
    assert (n - 1) / got["fps"] == pytest.approx(t[-1] - t[0], abs=1 / 60)
    rest, ends = rest_link_origins(), segment_ends_rest()
    idx = {k: i for i, k in enumerate(LINK_NAMES)}
    expect = {"left_hip": np.linalg.norm(rest[idx["left_knee"]] - rest[idx["left_hip"]]),
              "right_knee": np.linalg.norm(rest[idx["right_ankle"]] - rest[idx["right_knee"]]),
              "neck": np.linalg.norm(ends["neck"] - rest[idx["neck"]]),
              "left_ankle": np.linalg.norm(ends["left_ankle"] - rest[idx["left_ankle"]]),
              "right_elbow": np.linalg.norm(ends["right_wrist"] - rest[idx["right_elbow"]])}
    for bone, length in expect.items():
        assert got["bones"][bone] == pytest.approx(length, abs=1e-3), bone
    assert got["bones"]["neck"] > 0.2 and got["bones"]["left_ankle"] > 0.1

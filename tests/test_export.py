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
    # the same ticks the exporter picked (nearest to a 60 Hz clock)
    t = s.array("t")
    idx = np.clip(np.searchsorted(t, np.arange(t[0], t[-1] + 1e-9, 1 / 60)), 0, len(t) - 1)
    expected = bvh_local_quats(np.array([s.ticks[i]["link_quat_wxyz"] for i in idx]))
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
    assert root[0, 1] == pytest.approx(100 * s.ticks[idx[0]]["root_pos_world"][2], abs=1e-3)

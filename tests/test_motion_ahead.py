"""The motion stage a tick ahead of the controller (motion_ahead.py): in a forked worker it gives exactly what it
gives in line, the rows carry every field, and the worker's errors and death reach the session."""

import multiprocessing
import os
import threading

import numpy as np
import pytest

from stylesync.config import SessionConfig
from stylesync.errors import StylesyncError
from stylesync.motion.pose_optimization import MotionOptimizer
from stylesync.motion_ahead import pack_reference, pack_state, unpack_reference, unpack_state
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


def _session(duration_s: float, ahead: bool, on_tick=None) -> Session:
    """A session with the motion stage on the last tick's state: computed ahead in its worker or (``ahead`` False,
    the operator side prefetched all the same) in line."""
    cfg = SessionConfig(duration_s=duration_s, seed=1, motion_ahead=True)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, duration_s + 1.0, cfg.seed)
    session = Session(cfg, source, on_tick=on_tick)
    if not ahead:
        session.prefetch_operator = False  # (then the motion stage runs in line)
    return session


def _assert_same(a, b, where: str) -> None:
    """Dataclass values field by field: arrays bit for bit, dicts with their keys in the same order."""
    for name, va in vars(a).items():
        vb = getattr(b, name)
        if isinstance(va, dict):
            assert list(va) == list(vb), (where, name)
            for k in va:
                assert np.array_equal(va[k], vb[k]), (where, name, k)
        elif isinstance(va, np.ndarray):
            assert va.dtype == vb.dtype and np.array_equal(va, vb), (where, name)
        elif hasattr(va, "__dataclass_fields__"):
            _assert_same(va, vb, f"{where}.{name}")
        else:
            assert va == vb and type(va) is type(vb), (where, name, va, vb)


def test_rows_restore_the_state_and_the_reference_exactly():
    seen = []
    session = _session(4.0, ahead=False)
    session.on_tick = lambda state, ref: seen.append((state, ref, session.reading,
                                                      session.bounds.counts["step_length"]))
    session.run()
    kinds = set()
    for state, ref, reading, count in seen[::7]:
        _assert_same(unpack_state(pack_state(state)), state, "state")
        back, back_reading, back_count = unpack_reference(pack_reference(ref, reading, count))
        _assert_same(back, ref, "reference")
        assert back_reading.operator_stance is reading.operator_stance and back_reading.held == reading.held
        assert back_reading.operator_features.as_row() == reading.operator_features.as_row()
        assert back_count == count
        kinds.add((ref.lipm is None, ref.recovery_ankle_world is None, ref.character_stance))
    # the walk's ticks include single stances with the LIPM map, double stances without, and steps of its own
    assert {k[0] for k in kinds} == {True, False} and {k[1] for k in kinds} == {True, False}


def test_a_run_with_the_motion_stage_ahead_is_the_same_simulation_as_in_line():
    assert threading.active_count() == 1, f"threads left running: {threading.enumerate()}"
    ahead, inline = _session(3.0, ahead=True).run(), _session(3.0, ahead=False).run()
    assert ahead.operator_prefetched and not inline.operator_prefetched
    assert set(ahead.log.columns) == set(inline.log.columns)
    for key in ahead.log.columns:
        if key != "tick_ms":  # (wall time)
            assert np.array_equal(ahead.log.array(key), inline.log.array(key)), key
    assert ahead.bound_counts == inline.bound_counts
    assert not multiprocessing.active_children()  # both workers ended with the run


def test_the_motion_stage_reads_the_last_ticks_state_and_this_ticks_operator():
    refs, times, samples = [], [], []
    session = _session(0.3, ahead=False)
    session.on_tick = lambda state, ref: (refs.append(ref), times.append(state.time_s),
                                          samples.append(session.last_sample.time_s))
    session.run()
    assert refs[0].time_s == times[0]  # the first tick's own state
    assert [r.time_s for r in refs[1:]] == times[:-1]  # then the state of the tick before
    assert samples == times  # and the operator's sample of the tick itself


def test_by_default_the_motion_stage_reads_this_ticks_state_in_this_process():
    refs, times, children = [], [], []
    cfg = SessionConfig(duration_s=0.3, seed=1)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, 1.3, cfg.seed)
    session = Session(cfg, source, on_tick=lambda state, ref: (refs.append(ref), times.append(state.time_s),
                                                               children.append(len(multiprocessing.active_children()))))
    assert session.run().operator_prefetched
    assert [r.time_s for r in refs] == times
    assert max(children) == 1  # the operator side's worker alone


def _motion_stage_failing_at_tick_41(monkeypatch, fail) -> None:
    """The motion stage calls ``fail()`` at its 41st tick (the worker is forked with the patch)."""
    update = MotionOptimizer.update
    calls = []

    def failing(self, *args, **kwargs):
        calls.append(1)
        if len(calls) > 40:
            fail()
        return update(self, *args, **kwargs)

    monkeypatch.setattr(MotionOptimizer, "update", failing)


def test_an_error_of_the_motion_stage_reaches_the_session_and_leaves_no_process(monkeypatch):
    def fail():
        raise StylesyncError("the motion stage broke at its 41st tick")

    _motion_stage_failing_at_tick_41(monkeypatch, fail)
    with pytest.raises(StylesyncError, match="broke at its 41st tick"):
        _session(2.0, ahead=True).run()
    assert not multiprocessing.active_children()


def test_a_motion_worker_that_dies_is_reported(monkeypatch):
    _motion_stage_failing_at_tick_41(monkeypatch, lambda: os._exit(3))
    with pytest.raises(StylesyncError, match="motion-stage process ended unexpectedly"):
        _session(2.0, ahead=True).run()
    assert not multiprocessing.active_children()


def test_a_session_file_is_the_same_with_the_motion_stage_ahead(tmp_path):
    from stylesync.export.session_file import SessionRecorder, read_session

    lines = {}
    for ahead in (True, False):
        session = _session(3.0, ahead=ahead)
        path = tmp_path / f"{ahead}.jsonl"
        recorder = SessionRecorder(path, session.cfg, session, deferred=ahead)
        session.on_tick = recorder.tick
        session.run()
        recorder.close()
        lines[ahead] = path.read_text().splitlines()
    assert lines[True] == lines[False]
    ticks = read_session(tmp_path / "True.jsonl").ticks
    assert len(ticks) == len(lines[True]) - 1  # every tick's line, its operator reading included
    assert {t["operator_stance"] for t in ticks} >= {"DS", "LS", "RS"}

"""The operator side computed ahead in a second process (prefetch.py) gives exactly what the in-line path gives."""

import multiprocessing
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from stylesync.config import SessionConfig
from stylesync.errors import SourceError
from stylesync.motion.operator_analysis import analyse_operator
from stylesync.prefetch import OperatorPrefetch, pack, unpack
from stylesync.processing.operator_processing import OperatorProcessing
from stylesync.session import Session, control_tick_steps
from stylesync.sources.builtin_operator import builtin_operator


def _assert_same_sample(a, b) -> None:
    assert a.time_s == b.time_s and a.mocap_time_s == b.mocap_time_s
    for field in ("quat", "pos", "support_ankle_world"):
        da, db = getattr(a, field), getattr(b, field)
        assert list(da) == list(db), field
        for k in da:
            assert np.array_equal(da[k], db[k]), (field, k)
    assert np.array_equal(a.com_world, b.com_world)


def _assert_same_analysis(a, b) -> None:
    assert a.features.as_row() == b.features.as_row()
    assert np.array_equal(a.root_quat_wxyz, b.root_quat_wxyz)
    assert np.array_equal(a.upper_local_wxyz, b.upper_local_wxyz)
    assert a.leg_m == b.leg_m


def _walk_source(duration_s: float = 3.0):
    cfg = SessionConfig(duration_s=duration_s, seed=2)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, duration_s + 1.0, cfg.seed)
    return cfg, source


def test_pack_and_unpack_restore_every_field_exactly():
    cfg, source = _walk_source()
    proc = OperatorProcessing(cfg.clocks, cfg.filters)
    for t in (0.0, 0.5, 1.0):
        for f in source.poll(t):
            proc.push(f)
        sample = proc.step(t)
    analysis = analyse_operator(sample)
    back, back_analysis, rejected, dropped = unpack(pack(sample, analysis, 3, 7))
    _assert_same_sample(back, sample)
    _assert_same_analysis(back_analysis, analysis)
    assert (rejected, dropped) == (3, 7)


def test_prefetched_ticks_equal_the_in_line_ones():
    cfg, source = _walk_source()
    _, twin = _walk_source()
    dt, control_dt = 1.0 / cfg.clocks.physics_hz, 1.0 / cfg.clocks.control_hz
    times = [k * dt for k in control_tick_steps(int(round(cfg.duration_s * cfg.clocks.physics_hz)), dt, control_dt)]
    inline = OperatorProcessing(cfg.clocks, cfg.filters)
    ahead = OperatorProcessing(cfg.clocks, cfg.filters)
    for f in source.poll(0.0):
        inline.push(f)
    for f in twin.poll(0.0):
        ahead.push(f)
    prefetch = OperatorPrefetch(twin, ahead, times)
    try:
        for t in times:
            for f in source.poll(t):
                inline.push(f)
            expected = inline.step(t)
            got, analysis = prefetch.tick(t)
            _assert_same_sample(got, expected)
            assert analysis is not None
            _assert_same_analysis(analysis, analyse_operator(expected))
        assert prefetch.dropped_joint_values == inline.dropped_joint_values
    finally:
        prefetch.close()
    assert not multiprocessing.active_children()


def test_a_session_with_and_without_prefetch_is_the_same_simulation():
    def run(prefetch: bool):
        cfg, source = _walk_source(2.5)
        session = Session(cfg, source)
        session.prefetch_operator = prefetch
        return session.run()

    # Prefetch is off in a process with other threads (forking one is unsafe): a leaked thread would hide it.
    assert threading.active_count() == 1, f"threads left running: {threading.enumerate()}"
    ahead, inline = run(True), run(False)
    assert ahead.operator_prefetched and not inline.operator_prefetched
    for key in ("com_x", "com_y", "com_z", "root_z", "char_state", "joint_err_deg"):
        assert np.array_equal(ahead.log.array(key), inline.log.array(key)), key
    assert not multiprocessing.active_children()  # the worker ended with the run


def test_a_paced_run_computes_the_operator_side_in_line():
    cfg = SessionConfig(duration_s=0.2, seed=0, realtime=True)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, 1.0, cfg.seed)
    assert not Session(cfg, source).run().operator_prefetched


class _FailingSource:
    """A recorded source whose stream breaks at 0.5 s."""

    live = False
    rejected_frames = 0

    def __init__(self, inner):
        self.inner = inner

    def poll(self, now_s: float):
        if now_s > 0.5:
            raise SourceError("frame 9 of the recording is unreadable")
        return self.inner.poll(now_s)

    def close(self) -> None:
        self.inner.close()


def test_an_error_of_the_operator_side_reaches_the_session_and_leaves_no_process():
    cfg, source = _walk_source()
    session = Session(cfg, _FailingSource(source))
    with pytest.raises(SourceError, match="frame 9 of the recording is unreadable"):
        session.run()
    assert not multiprocessing.active_children()


def test_a_worker_that_dies_is_reported_as_a_source_error():
    cfg, source = _walk_source()
    proc = OperatorProcessing(cfg.clocks, cfg.filters)
    for f in source.poll(0.0):
        proc.push(f)
    times = [k / 133.0 for k in range(1300)]
    prefetch = OperatorPrefetch(source, proc, times)
    try:
        prefetch.tick(times[0])
        prefetch._proc.kill()
        prefetch._proc.join(5.0)
        with pytest.raises(SourceError, match="ended unexpectedly"):
            for t in times[1:]:
                prefetch.tick(t)
    finally:
        prefetch.close()


def _process_running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("motion_ahead", [False, True])
def test_the_workers_end_when_their_session_is_killed(motion_ahead):
    # Killed (SIGKILL), the session cannot end its workers: each must notice (its pipe has no other end left). With
    # the motion stage ahead (motion_ahead.py) it has two.
    script = f"""
import multiprocessing, sys
from stylesync.config import SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator
cfg = SessionConfig(duration_s=60.0, seed=0, motion_ahead={motion_ahead})
source, _ = builtin_operator(cfg.operator, cfg.clocks, 61.0, 0)
told = []
def on_tick(state, ref):
    if not told:
        told.append(1)
        print("workers:", *(p.pid for p in multiprocessing.active_children()), flush=True)
Session(cfg, source, on_tick=on_tick).run()
"""
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        line = next((ln for ln in proc.stdout if ln.startswith("workers:")), "")  # the engine prints too
        workers = [int(p) for p in line.split()[1:]]
        assert len(workers) == (2 if motion_ahead else 1), "the session did not start its workers"
        proc.kill()
        proc.wait(timeout=10)
        deadline = time.monotonic() + 5.0
        while any(_process_running(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(_process_running(w) for w in workers), "a worker outlived its killed session"
    finally:
        if proc.poll() is None:
            proc.kill()

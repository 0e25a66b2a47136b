"""The operator side of the pipeline, run ahead of the control ticks in a second process (offline runs).

Polling the source, the interpolation to the control rate (Eq. 7), the 1€ filter (Eq. 8), the floor filters and the
operator's style features (Sec. 5.2, with the joint-map rotations of the upper body) depend on the operator stream
alone, never on the character. In an offline run of a recorded operator the control ticks' times are known in
advance, so a forked worker can compute all of it ahead of the physics loop, on the second core, and hand each
control tick its operator sample; the main process spends its ticks on the character (motion, control, physics).

The worker runs the same code on the same inputs as the in-line path (``OperatorInline``): the samples are
bit-identical (a test checks it), and so is the simulation. Values cross the pipe as float64 rows, packed and
unpacked by field (pickling ~40 small arrays per tick would cost more than computing them).

Used only when nothing else can touch the operator side during the run and forking is safe: not paced to the wall
clock, headless, a recorded source (not live), no other thread in the process, on Linux.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Sequence
from multiprocessing.connection import Connection

import numpy as np

from stylesync.errors import SourceError
from stylesync.motion.operator_analysis import UPPER_JOINTS, OperatorAnalysis, analyse_operator
from stylesync.motion.style_features import ROW_NAMES, StyleFeatures
from stylesync.processing.joint_map import TRACKED_ORIENTATIONS, TRACKED_POSITIONS
from stylesync.processing.operator_processing import OperatorProcessing, OperatorSample
from stylesync.sources.base import OperatorSource

BATCH_TICKS = 32  # control ticks per message from the worker (about 35 kB)
WORKER_EXIT_TIMEOUT_S = 2.0
# The worker runs ahead by up to a pipe's worth of batches: it yields a core to the session and to the motion
# stage's worker (motion_ahead.py), which wait on each other at every tick [nice increment]
WORKER_NICENESS = 10

# Row layout: time, mocap time, rejected frames, dropped joint values (the last two cumulative), then the sample's
# and the analysis's arrays.
_SIDES = ("left", "right")
_FIELDS: list[tuple[str, int]] = [("time_s", 1), ("mocap_time_s", 1), ("rejected", 1), ("dropped", 1),
                                  ("quat", 4 * len(TRACKED_ORIENTATIONS)), ("pos", 3 * len(TRACKED_POSITIONS)),
                                  ("com", 3), ("support", 3 * len(_SIDES)), ("features", len(ROW_NAMES)),
                                  ("root", 4), ("upper", 4 * len(UPPER_JOINTS)), ("leg", 1)]


def row_layout(fields: list[tuple[str, int]]) -> tuple[dict[str, slice], int]:
    """Each named field's slice of a float64 row holding ``fields`` (name, size) in order, and the row's width."""
    out, offset = {}, 0
    for name, size in fields:
        out[name] = slice(offset, offset + size)
        offset += size
    return out, offset


_SLICE, ROW_WIDTH = row_layout(_FIELDS)


def pack(sample: OperatorSample, analysis: OperatorAnalysis, rejected: int, dropped: int) -> np.ndarray:
    """(ROW_WIDTH,) float64 row of one control tick's operator side."""
    row = np.empty(ROW_WIDTH)
    row[_SLICE["time_s"]] = sample.time_s
    row[_SLICE["mocap_time_s"]] = sample.mocap_time_s
    row[_SLICE["rejected"]] = rejected
    row[_SLICE["dropped"]] = dropped
    row[_SLICE["quat"]] = np.concatenate([sample.quat[n] for n in TRACKED_ORIENTATIONS])
    row[_SLICE["pos"]] = np.concatenate([sample.pos[n] for n in TRACKED_POSITIONS])
    row[_SLICE["com"]] = sample.com_world
    row[_SLICE["support"]] = np.concatenate([sample.support_ankle_world[s] for s in _SIDES])
    row[_SLICE["features"]] = analysis.features.as_row()
    row[_SLICE["root"]] = analysis.root_quat_wxyz
    row[_SLICE["upper"]] = analysis.upper_local_wxyz.reshape(-1)
    row[_SLICE["leg"]] = analysis.leg_m
    return row


def unpack(row: np.ndarray) -> tuple[OperatorSample, OperatorAnalysis, int, int]:
    """The inverse of :func:`pack`: the sample, its analysis, rejected frames and dropped joint values."""
    sample = OperatorSample(
        time_s=float(row[0]),
        quat=dict(zip(TRACKED_ORIENTATIONS, row[_SLICE["quat"]].reshape(-1, 4), strict=True)),
        pos=dict(zip(TRACKED_POSITIONS, row[_SLICE["pos"]].reshape(-1, 3), strict=True)),
        com_world=row[_SLICE["com"]],
        support_ankle_world=dict(zip(_SIDES, row[_SLICE["support"]].reshape(-1, 3), strict=True)),
        mocap_time_s=float(row[1]),
    )
    analysis = OperatorAnalysis(StyleFeatures.from_row(row[_SLICE["features"]]), row[_SLICE["root"]],
                                row[_SLICE["upper"]].reshape(-1, 4), float(row[_SLICE["leg"]][0]))
    return sample, analysis, int(row[2]), int(row[3])


class OperatorInline:
    """The operator side computed at each control tick, in this process (live sources, paced runs, viewers)."""

    def __init__(self, source: OperatorSource, processing: OperatorProcessing):
        self.source = source
        self.processing = processing

    def poll(self, time_s: float) -> list:
        """Frames of the source due by ``time_s``, pushed into the processing; returned for the caller's checks."""
        frames = self.source.poll(time_s)
        for f in frames:
            self.processing.push(f)
        return frames

    def tick(self, time_s: float) -> tuple[OperatorSample, OperatorAnalysis | None]:
        return self.processing.step(time_s), None

    @property
    def rejected_frames(self) -> int:
        return int(getattr(self.source, "rejected_frames", 0))

    @property
    def dropped_joint_values(self) -> int:
        return self.processing.dropped_joint_values

    def close(self) -> None:
        """Nothing to release (the session closes the source)."""


def _worker(conn: Connection, session_end: Connection, source: OperatorSource, processing: OperatorProcessing,
            tick_times_s: Sequence[float]) -> None:
    """The forked process: every control tick's operator side, in batches, then ("end",) or ("error", exception)."""
    # The fork copied the session's end of the pipe too: closed here, a session that dies (even killed) leaves no
    # reader, and the next send fails instead of waiting forever.
    session_end.close()
    worker_signals()
    os.nice(WORKER_NICENESS)
    rows: list[np.ndarray] = []
    batch = 1  # the first tick at once, so that the run starts without waiting for a whole batch
    try:
        try:
            for t in tick_times_s:
                for f in source.poll(t):
                    processing.push(f)
                sample = processing.step(t)
                rows.append(pack(sample, analyse_operator(sample), int(getattr(source, "rejected_frames", 0)),
                                 processing.dropped_joint_values))
                if len(rows) == batch:
                    conn.send(("rows", np.stack(rows).tobytes()))
                    rows, batch = [], BATCH_TICKS
        except Exception as exc:  # delivered at the tick where it happened, raised there by the session
            if rows:
                conn.send(("rows", np.stack(rows).tobytes()))
            try:
                conn.send(("error", exc))
            except Exception:  # an exception that cannot be pickled: its type and message
                conn.send(("error", SourceError(f"operator side: {type(exc).__name__}: {exc}")))
            return
        if rows:
            conn.send(("rows", np.stack(rows).tobytes()))
        conn.send(("end", None))
    except (BrokenPipeError, EOFError, OSError):  # the session has gone: nothing to deliver to
        return


def start_forked(proc: multiprocessing.process.BaseProcess) -> None:
    """Start a forked worker. It is ended by SIGTERM when the run no longer needs it, possibly while it is still
    starting; it must not inherit a handler of the session's (the command line turns SIGTERM into KeyboardInterrupt),
    which would print an ignored exception. The signal is held while forking and restored to its default in the
    worker (:func:`worker_signals`)."""
    held = threading.current_thread() is threading.main_thread()
    if held:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
    try:
        proc.start()
    finally:
        if held:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})


def worker_signals() -> None:
    """In a worker forked by :func:`start_forked`: the session ends it (SIGTERM, restored); a terminal's Ctrl-C is
    the session's."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})


class OperatorPrefetch:
    """The operator side of the listed control ticks, computed ahead by a forked worker (see the module's notes).

    ``tick(t)`` must be called for those times in order. The worker starts from the current state of ``source``
    and ``processing`` (copied by the fork); they are not advanced in this process.
    """

    def __init__(self, source: OperatorSource, processing: OperatorProcessing, tick_times_s: Sequence[float]):
        ctx = multiprocessing.get_context("fork")
        self._conn, child = ctx.Pipe(duplex=False)
        self._proc = ctx.Process(target=_worker, args=(child, self._conn, source, processing, list(tick_times_s)),
                                 name="stylesync-operator", daemon=True)
        start_forked(self._proc)
        child.close()
        self._rows = np.zeros((0, ROW_WIDTH))
        self._next = 0
        self.last_row = np.zeros(ROW_WIDTH)  # the row of the last tick (motion_ahead.py forwards it)
        self._remaining = len(tick_times_s)
        self._rejected = int(getattr(source, "rejected_frames", 0))
        self._dropped = processing.dropped_joint_values

    @staticmethod
    def usable(source: OperatorSource, realtime: bool, gui: bool) -> bool:
        """Whether a run may prefetch: offline, headless, a recorded source, no other thread, and Linux (where
        forking a process that has used numpy's BLAS and the engine is safe)."""
        return (not realtime and not gui and not getattr(source, "live", False) and threading.active_count() == 1
                and sys.platform.startswith("linux"))

    def poll(self, time_s: float) -> list:
        """The worker polls the source; nothing to do here."""
        return []

    def tick(self, time_s: float) -> tuple[OperatorSample, OperatorAnalysis | None]:
        if self._next == len(self._rows):
            self._receive()
        row = self.last_row = self._rows[self._next]
        self._next += 1
        self._remaining -= 1
        sample, analysis, self._rejected, self._dropped = unpack(row)
        if sample.time_s != time_s:
            raise RuntimeError(f"operator prefetch out of step: sample for t={sample.time_s} at t={time_s}")
        return sample, analysis

    def next_row(self) -> np.ndarray | None:
        """The row of the control tick after the last one ticked, without moving on to it (motion_ahead.py runs the
        motion stage on it a tick ahead); None after the last tick."""
        if self._remaining == 0:
            return None
        if self._next == len(self._rows):
            self._receive()
        return self._rows[self._next]

    def _receive(self) -> None:
        try:
            kind, payload = self._conn.recv()
        except (EOFError, OSError):
            raise SourceError("the operator-side process ended unexpectedly") from None
        if kind == "error":
            raise payload
        if kind != "rows":
            raise SourceError("the operator stream ended before the run (the operator side delivered no more ticks)")
        self._rows = np.frombuffer(payload).reshape(-1, ROW_WIDTH)
        self._next = 0

    @property
    def rejected_frames(self) -> int:
        return self._rejected

    @property
    def dropped_joint_values(self) -> int:
        return self._dropped

    def close(self) -> None:
        """End the worker (it may still be computing ticks the run did not reach) and release the pipe."""
        self._conn.close()
        if self._proc.is_alive():
            self._proc.terminate()
        self._proc.join(WORKER_EXIT_TIMEOUT_S)

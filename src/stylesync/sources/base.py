"""Operator sources: anything that yields :class:`OperatorFrame` values in time order."""

from __future__ import annotations

import json
import logging
import threading
import time
from abc import ABC, abstractmethod
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from stylesync.errors import SourceError
from stylesync.sources.frame import OperatorFrame

log = logging.getLogger("stylesync.sources")


def read_json_file(path: str | Path, what: str) -> Any:
    """The parsed content of a JSON file; a missing or unreadable file, or invalid JSON, is a one-line
    SourceError naming ``what`` the file was meant to be."""
    p = Path(path)
    try:
        return json.loads(p.read_text())
    except FileNotFoundError:
        raise SourceError(f"{what} not found: {p}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise SourceError(f"{what} {p} is not valid JSON: {exc}".splitlines()[0]) from None


class OperatorSource(ABC):
    """A stream of operator frames. ``poll(now_s)`` returns the frames that have arrived by ``now_s`` [s]."""

    rejected_frames: int = 0

    @abstractmethod
    def poll(self, now_s: float) -> list[OperatorFrame]: ...

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release devices or sockets."""


class RecordedSource(OperatorSource):
    """Frames known in advance (a file or a clip), released as their timestamps come due.

    Frames with non-finite values or going back in time are rejected, counted and logged, never passed on.
    """

    def __init__(self, frames: list[OperatorFrame], name: str = "recorded", starts_in_motion: bool = False):
        self.name = name
        # The character starts in the first frame's pose and velocities (motion/initial_state.py), not standing.
        self.starts_in_motion = starts_in_motion
        self.rejected_frames = 0
        clean: list[OperatorFrame] = []
        last_t = -np.inf
        for f in frames:
            if not f.is_finite() or not np.isfinite(f.timestamp_s):
                self._reject(f, "non-finite values")
                continue
            if f.timestamp_s <= last_t:
                self._reject(f, f"timestamp {f.timestamp_s:.3f} s not after {last_t:.3f} s")
                continue
            clean.append(f)
            last_t = f.timestamp_s
        self.frames = clean
        self._next = 0

    def _reject(self, f: OperatorFrame, why: str) -> None:
        self.rejected_frames += 1
        log.warning("%s: rejected frame at %.3f s (%s)", self.name, f.timestamp_s, why)

    @property
    def duration_s(self) -> float:
        return self.frames[-1].timestamp_s if self.frames else 0.0

    def poll(self, now_s: float) -> list[OperatorFrame]:
        out: list[OperatorFrame] = []
        while self._next < len(self.frames) and self.frames[self._next].timestamp_s <= now_s + 1e-9:
            out.append(self.frames[self._next])
            self._next += 1
        return out


class QueuedLiveSource(OperatorSource):
    """A live stream: a receiving thread ``push``es frames; ``poll`` hands over those that arrived since the last
    call. Each frame carries its arrival time in ``extras["arrival_wall_s"]`` (``time.perf_counter``)."""

    live = True

    def __init__(self, max_queue: int):
        self.rejected_frames = 0
        self.rejections: dict[str, int] = {}  # rejected packets or frames by reason
        self._queue: deque[OperatorFrame] = deque(maxlen=max_queue)
        self._lock = threading.Lock()

    def count_rejection(self, reason: str) -> int:
        """Count one rejection of ``reason``; returns how many of that reason so far."""
        with self._lock:
            n = self.rejections[reason] = self.rejections.get(reason, 0) + 1
        return n

    def push(self, frame: OperatorFrame) -> None:
        """Queue a frame; when the queue is full the oldest frame is dropped and counted ("queue overflow")."""
        with self._lock:
            overflow = len(self._queue) == self._queue.maxlen
            self._queue.append(frame)
        if overflow:
            self.rejected_frames += 1
            if self.count_rejection("queue overflow") == 1:
                log.warning("operator stream: frames arrive faster than they are used; the oldest are dropped")

    def poll(self, now_s: float) -> list[OperatorFrame]:
        with self._lock:
            frames = list(self._queue)
            self._queue.clear()
        return frames

    def wait_first_frame(self, timeout_s: float) -> bool:
        """Block until a frame has arrived (True) or the timeout passes (False)."""
        end = time.perf_counter() + timeout_s
        while time.perf_counter() < end:
            with self._lock:
                if self._queue:
                    return True
            time.sleep(0.005)
        return False

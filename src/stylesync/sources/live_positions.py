"""Shared machinery of live sources that report joint positions only (MediaPipe, Azure Kinect): a capture thread
fills a queue of operator frames, with orientations derived from positions and the floor under the lowest ankle
seen so far."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import numpy as np

from stylesync.sources.base import QueuedLiveSource
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame
from stylesync.sources.segment_frames import canonical_quats_from_positions
from stylesync.sources.skeleton_tracks import WINTER_ANKLE_PER_HIP_TO_ANKLE, fill_canonical

log = logging.getLogger("stylesync.sources")


class LivePositionSource(QueuedLiveSource):
    """``read()`` (run on a thread) returns (positions (32, 3) world [m], confidence (32,)) or None at the end."""

    def __init__(self, read: Callable[[], tuple[np.ndarray, np.ndarray] | None], name: str, max_queue: int = 64):
        super().__init__(max_queue)
        self.name = name
        self._read = read
        self._stop = threading.Event()
        self._lowest_ankle = np.inf
        self._t0 = time.perf_counter()
        self._thread = threading.Thread(target=self._loop, name=f"{name}-capture", daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        while not self._stop.is_set():
            got = self._read()
            if got is None:
                return
            pos, conf = got
            arrival = time.perf_counter()
            if pos.shape != (N_JOINTS, 3) or not np.all(np.isfinite(pos)):
                self.rejected_frames += 1
                log.warning("%s: rejected frame (missing or non-finite joints)", self.name)
                continue
            pos = pos.copy()
            ankles = pos[[JOINT_INDEX["ANKLE_LEFT"], JOINT_INDEX["ANKLE_RIGHT"]], 2]
            self._lowest_ankle = min(self._lowest_ankle, float(ankles.min()))
            leg = float(np.linalg.norm(pos[JOINT_INDEX["HIP_LEFT"]] - pos[JOINT_INDEX["ANKLE_LEFT"]]))
            pos[:, 2] += WINTER_ANKLE_PER_HIP_TO_ANKLE * leg - self._lowest_ankle
            P, C = pos[None], conf[None].copy()
            Q = canonical_quats_from_positions(P)
            fill_canonical(P, Q, C)
            frame = OperatorFrame(arrival - self._t0, P[0], Q[0], C[0])
            frame.extras["arrival_wall_s"] = arrival
            self.push(frame)

    def close(self) -> None:
        self._stop.set()

"""Replay a session file without re-simulating: pose the character from the recorded states to render video,
and export BVH."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stylesync.config import WorldConfig
from stylesync.export.bvh_export import write_bvh
from stylesync.export.session_file import SessionFile
from stylesync.export.video import write_mp4
from stylesync.model.character import STANDING_ROOT_HEIGHT_M
from stylesync.sim.factory import make_backend


def rest_link_origins() -> np.ndarray:
    """Link origins (n_links, 3) [m] of the character standing in its rest pose (all joints zero)."""
    backend = make_backend(WorldConfig(), 600.0)
    try:
        backend.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M]), np.array([1.0, 0.0, 0.0, 0.0]))
        return backend.read_state(0.0).link_origin_world.copy()
    finally:
        backend.close()


def resample_ticks(session: SessionFile, fps: float) -> list[dict]:
    """The recorded ticks nearest to a uniform clock at ``fps``."""
    t = session.array("t")
    if len(t) == 0:
        return []
    grid = np.arange(t[0], t[-1] + 1e-9, 1.0 / fps)
    idx = np.clip(np.searchsorted(t, grid), 0, len(t) - 1)
    return [session.ticks[i] for i in idx]


def export_bvh(session: SessionFile, path: str | Path, fps: float = 60.0) -> int:
    """The character's motion as BVH with a Frame Time of exactly 1 / ``fps`` (a player then plays it at the
    session's speed), one frame per tick of that clock (the recorded tick nearest it). Returns the frame count."""
    ticks = resample_ticks(session, fps)
    times = np.array([tk["t"] for tk in ticks])
    write_bvh(path, times, np.array([tk["root_pos_world"] for tk in ticks]),
              np.array([tk["link_quat_wxyz"] for tk in ticks]), rest_link_origins(), frame_time_s=1.0 / fps)
    return len(ticks)


def posed_backend(ticks: list[dict]):
    """For each recorded tick, a backend posed kinematically in that tick's state (no simulation): yields
    (tick, backend); the backend is closed when the iteration ends."""
    backend = make_backend(WorldConfig(), 600.0)
    try:
        for tk in ticks:
            backend.reset(np.array(tk["root_pos_world"]), np.array(tk["root_quat_wxyz"]), np.array(tk["joint_pos"]))
            yield tk, backend
    finally:
        backend.close()


def export_mp4(session: SessionFile, path: str | Path, fps: float = 30.0, width: int = 480, height: int = 360) -> int:
    frames = []
    for tk, backend in posed_backend(resample_ticks(session, fps)):
        target = [tk["root_pos_world"][0], tk["root_pos_world"][1], 0.8]
        frames.append(backend.render_rgb(target, width=width, height=height))  # type: ignore[attr-defined]
    write_mp4(path, frames, fps)
    return len(frames)

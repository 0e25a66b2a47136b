"""Replay a session file without re-simulating: pose the character from the recorded states to render video,
and export BVH."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.export.bvh_export import write_bvh
from stylesync.export.session_file import SessionFile
from stylesync.export.video import write_mp4
from stylesync.model.character import LINK_NAMES, STANDING_ROOT_HEIGHT_M
from stylesync.model.state import CharacterState, LinkShape
from stylesync.sim.factory import make_backend


def _rest_pose() -> tuple[CharacterState, list[LinkShape]]:
    """The character standing in its rest pose (all joints zero, facing +x), and its collision shapes."""
    backend = make_backend(WorldConfig(), 600.0)
    try:
        backend.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M]), np.array([1.0, 0.0, 0.0, 0.0]))
        return backend.read_state(0.0), backend.collision_shapes()
    finally:
        backend.close()


def rest_link_origins() -> np.ndarray:
    """Link origins (n_links, 3) [m] of the character standing in its rest pose (all joints zero)."""
    return _rest_pose()[0].link_origin_world.copy()


def segment_ends_rest() -> dict[str, np.ndarray]:
    """Where the character's end segments end in its rest pose (all joints zero, standing, facing +x) [m], from
    the engine's collision shapes: the hands' tips (the wrist links' shapes, furthest along the forearm), the toes'
    tips (the foot shapes' front edge, at the sole) and the top of the head (the neck link's shape, highest)."""
    state, shapes = _rest_pose()
    points: dict[int, list[np.ndarray]] = {}
    for shape in shapes:
        # The rest pose's canonical link orientations are the identity: link axes are world axes.
        centre = state.link_com_world[shape.link] + shape.pos_link
        points.setdefault(shape.link, []).extend(_shape_points(shape.kind, shape.size, centre, shape.quat_link_wxyz))
    idx = {n: i for i, n in enumerate(LINK_NAMES)}
    ends = {}
    for side in ("left", "right"):
        hand = np.array(points[idx[f"{side}_wrist"]])
        along = state.link_origin_world[idx[f"{side}_wrist"]] - state.link_origin_world[idx[f"{side}_elbow"]]
        along /= np.linalg.norm(along)
        wrist = state.link_origin_world[idx[f"{side}_wrist"]]
        ends[f"{side}_wrist"] = wrist + along * float(np.max((hand - wrist) @ along))
        foot = np.array(points[idx[f"{side}_ankle"]])
        ankle = state.link_origin_world[idx[f"{side}_ankle"]]
        ends[f"{side}_ankle"] = np.array([float(foot[:, 0].max()), ankle[1], float(foot[:, 2].min())])
    head = np.array(points[idx["neck"]])
    neck = state.link_origin_world[idx["neck"]]
    ends["neck"] = np.array([neck[0], neck[1], float(head[:, 2].max())])
    return ends


def _shape_points(kind: str, size: tuple[float, ...], centre: np.ndarray, quat_wxyz: np.ndarray) -> list[np.ndarray]:
    """Points whose hull bounds a collision shape well enough for its extremes along the axes: a sphere's six
    poles, a capsule's end caps' poles, a box's corners [m]."""
    R = rot.matrix_from_quat(quat_wxyz)
    axes = [np.array(v, dtype=float) for v in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))]
    if kind == "sphere":
        return [centre + size[0] * a for a in axes]
    if kind == "capsule":
        half = R @ np.array([0.0, 0.0, size[0] / 2])
        return [centre + e + size[1] * a for e in (half, -half) for a in axes]
    hx, hy, hz = (d / 2 for d in size[:3])
    return [centre + R @ np.array([sx * hx, sy * hy, sz * hz]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def interpolated_motion(session: SessionFile, fps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The character's motion at a uniform clock of ``fps`` from the session's first tick to its last: times (T,)
    [s], root positions (T, 3) [m] interpolated linearly, canonical link orientations (T, n_links, 4) by slerp,
    between the two recorded ticks around each time."""
    t = session.array("t")
    if len(t) == 0:
        return np.zeros(0), np.zeros((0, 3)), np.zeros((0, len(LINK_NAMES), 4))
    grid = np.arange(t[0], t[-1] + 1e-9, 1.0 / fps)
    pos = session.array("root_pos_world")
    quat = session.array("link_quat_wxyz")
    hi = np.clip(np.searchsorted(t, grid), 0, len(t) - 1)
    lo = np.maximum(hi - 1, 0)
    span = np.where(t[hi] > t[lo], t[hi] - t[lo], 1.0)
    w = np.clip((grid - t[lo]) / span, 0.0, 1.0)
    root = pos[lo] + w[:, None] * (pos[hi] - pos[lo])
    links = np.array([rot.batch_slerp(quat[a], quat[b], float(f)) for a, b, f in zip(lo, hi, w, strict=True)])
    return grid, root, links


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
    session's speed), resampled at that clock (interpolated between the recorded ticks), its end sites at the
    character's segment ends. Returns the frame count."""
    times, root, links = interpolated_motion(session, fps)
    write_bvh(path, times, root, links, rest_link_origins(), frame_time_s=1.0 / fps,
              end_sites_world=segment_ends_rest())
    return len(times)


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

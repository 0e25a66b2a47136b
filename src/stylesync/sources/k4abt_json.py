"""Azure Kinect Body Tracking recordings in the JSON of the SDK's offline processor (``k4a-json:PATH``).

Layout (Azure-Kinect-Samples ``body-tracking-samples/offline_processor``)::

    {"k4abt_sdk_version": ..., "joint_names": [32 names], "bone_list": [...],
     "frames": [{"frame_id": n, "timestamp_usec": t, "num_bodies": k,
                 "bodies": [{"body_id": id, "joint_positions": [[x, y, z] mm] * 32,
                             "joint_orientations": [[w, x, y, z]] * 32}]}]}

Positions are in the depth camera frame (x right, y down, z away from the camera) in millimetres. We assume a
level camera: world x = camera z, world y = -camera x, world z = -camera y, and put the floor under the lowest
ankle of the recording (sources/skeleton_tracks.py, ``place_on_floor``). The SDK's joint orientations use a
per-joint axis convention of its own, so segment orientations are derived from the joint positions
(sources/segment_frames.py), unless the file was written by :func:`write_k4abt_json`, which stores canonical
orientations and says so (``"stylesync_orientation": "canonical-camera"``). The first tracked body is followed by
its ``body_id``; frames without it, with NaN, with the wrong joint count or going back in time are rejected,
counted and logged.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.base import read_json_file
from stylesync.sources.frame import K4ABT_JOINTS, N_JOINTS, OperatorFrame
from stylesync.sources.limits import MAX_RECORDING_S, distance_problem, frame_interval_problem
from stylesync.sources.segment_frames import canonical_quats_from_positions
from stylesync.sources.skeleton_tracks import TrackPerformer, place_on_floor

log = logging.getLogger("stylesync.sources")
R_WORLD_CAMERA = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # level depth camera
Q_WORLD_CAMERA = rot.quat_from_matrix(R_WORLD_CAMERA)
CANONICAL_TAG = "canonical-camera"


class K4abtRecording:
    """A k4abt JSON recording on the canonical skeleton; ``performer`` replays it."""

    def __init__(self, path: str | Path):
        p = Path(path)
        data = read_json_file(p, "k4abt JSON file")
        if not isinstance(data, dict) or not isinstance(data.get("frames"), list):
            raise SourceError(f"k4abt JSON {p}: expected an object with a 'frames' list")
        names = data.get("joint_names")
        if names is not None and list(names) != list(K4ABT_JOINTS):
            raise SourceError(f"k4abt JSON {p}: joint_names differ from the 32 Body Tracking joints")
        canonical = data.get("stylesync_orientation") == CANONICAL_TAG
        self.rejected_frames = 0
        body_id = None
        times: list[float] = []
        positions: list[np.ndarray] = []
        quats: list[np.ndarray] = []
        for k, fr in enumerate(data["frames"]):
            why, body = self._body_of(fr, body_id)
            if body is None:
                self._reject(p, k, why)
                continue
            try:
                t = float(fr["timestamp_usec"]) * 1e-6
                pos = np.array(body["joint_positions"], dtype=float)
                q = np.array(body["joint_orientations"], dtype=float) if canonical else None
            except (KeyError, TypeError, ValueError):
                self._reject(p, k, "missing or non-numeric timestamp_usec, joint_positions or joint_orientations")
                continue
            if pos.shape != (N_JOINTS, 3) or (q is not None and q.shape != (N_JOINTS, 4)):
                self._reject(p, k, f"expected {N_JOINTS} joints of 3 (positions) and 4 (orientations) values")
                continue
            if not (np.isfinite(t) and np.all(np.isfinite(pos)) and (q is None or np.all(np.isfinite(q)))):
                self._reject(p, k, "NaN or infinite values")
                continue
            if times and t <= times[-1]:
                self._reject(p, k, f"timestamp {t:.6f} s not after {times[-1]:.6f} s")
                continue
            # Frames may be seconds apart where the tracker lost the person; a recording is at most a day long.
            if times and (problem := frame_interval_problem(t - times[-1], MAX_RECORDING_S - (times[-1] - times[0]))):
                self._reject(p, k, problem)
                continue
            if positions and (problem := distance_problem(pos @ R_WORLD_CAMERA.T * 1e-3, positions[0][0])):
                self._reject(p, k, problem)
                continue
            body_id = body.get("body_id", body_id)
            times.append(t)
            positions.append(pos @ R_WORLD_CAMERA.T * 1e-3)
            if q is not None:
                qn = q / np.maximum(np.linalg.norm(q, axis=1, keepdims=True), 1e-12)
                quats.append(rot.batch_multiply(np.tile(Q_WORLD_CAMERA, (N_JOINTS, 1)), qn))
        if len(times) < 2:
            raise SourceError(f"k4abt JSON {p}: fewer than two usable frames ({self.rejected_frames} rejected)")
        P = np.array(positions)
        place_on_floor(P)
        Q = np.array(quats) if quats else canonical_quats_from_positions(P)
        self.path = p
        self.performer = TrackPerformer(np.array(times), P, Q, np.ones((len(times), N_JOINTS)),
                                        name=f"k4a-json:{p.name}")

    @staticmethod
    def _body_of(fr: object, body_id: object) -> tuple[str, dict | None]:
        if not isinstance(fr, dict):
            return "frame is not an object", None
        bodies = fr.get("bodies")
        if not isinstance(bodies, list) or not bodies:
            return "no body tracked", None
        for b in bodies:
            if isinstance(b, dict) and (body_id is None or b.get("body_id") == body_id):
                return "", b
        return f"body {body_id} not tracked", None

    def _reject(self, p: Path, k: int, why: str) -> None:
        self.rejected_frames += 1
        log.warning("k4a-json %s: rejected frame %d (%s)", p.name, k, why)


def write_k4abt_json(frames: list[OperatorFrame], path: str | Path, camera_in_world_m=(-2.5, 0.0, 1.0)) -> None:
    """Write operator frames as an offline-processor JSON (positions in mm in a level depth camera's frame placed
    at ``camera_in_world_m``), storing canonical orientations rotated into the camera frame."""
    cam = np.asarray(camera_in_world_m, dtype=float)
    q_cw = rot.conjugate(Q_WORLD_CAMERA)
    out_frames = []
    for k, f in enumerate(frames):
        pos_cam = (f.joint_pos_world - cam) @ R_WORLD_CAMERA * 1e3
        q_cam = rot.batch_multiply(np.tile(q_cw, (N_JOINTS, 1)), f.joint_quat_wxyz)
        out_frames.append({
            "frame_id": k, "timestamp_usec": int(round(f.timestamp_s * 1e6)), "num_bodies": 1,
            "bodies": [{"body_id": 1, "joint_positions": np.round(pos_cam, 3).tolist(),
                        "joint_orientations": np.round(q_cam, 7).tolist()}],
        })
    doc = {"k4abt_sdk_version": "1.1.2", "source_file": "stylesync", "stylesync_orientation": CANONICAL_TAG,
           "joint_names": list(K4ABT_JOINTS), "frames": out_frames}
    Path(path).write_text(json.dumps(doc))

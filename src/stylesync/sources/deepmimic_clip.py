"""DeepMimic motion clips (``humanoid3d_*.txt``) as recorded operators.

A clip is JSON: ``{"Loop": "wrap"|"none", "Frames": [[dt, root_pos(3), root_rot(4), chest(4), neck(4),
right_hip(4), right_knee, right_ankle(4), right_shoulder(4), right_elbow, left_hip(4), left_knee, left_ankle(4),
left_shoulder(4), left_elbow], ...]}``, Y up, quaternions (w, x, y, z) in the humanoid model's axes, positions in
metres at the 0.25-scaled character size. We convert to our z-up world and canonical axes here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.model.character import Q_WORLD_MODEL, canonical_quat_from_model
from stylesync.sources.base import read_json_file
from stylesync.sources.limits import distance_problem, frame_interval_problem

FRAME_WIDTH = 44
# (canonical joint, kind, width) in clip order after dt, root position and root rotation.
_CLIP_LAYOUT: tuple[tuple[str, str, int], ...] = (
    ("SPINE_CHEST", "ball", 4), ("NECK", "ball", 4),
    ("HIP_RIGHT", "ball", 4), ("KNEE_RIGHT", "hinge", 1), ("ANKLE_RIGHT", "ball", 4),
    ("SHOULDER_RIGHT", "ball", 4), ("ELBOW_RIGHT", "hinge", 1),
    ("HIP_LEFT", "ball", 4), ("KNEE_LEFT", "hinge", 1), ("ANKLE_LEFT", "ball", 4),
    ("SHOULDER_LEFT", "ball", 4), ("ELBOW_LEFT", "hinge", 1),
)
# Hinges turn about the model's z axis, which is world -y in canonical axes.
HINGE_AXIS_CANONICAL = np.array([0.0, -1.0, 0.0])
CLIP_CHARACTER_LEG_LENGTH_M = 0.899  # hip joint height of the clip's character with straight legs [m]


def pybullet_clip_path(name: str) -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath()) / "data" / "motions" / f"humanoid3d_{name}.txt"


def builtin_clip_names() -> list[str]:
    import pybullet_data

    folder = Path(pybullet_data.getDataPath()) / "data" / "motions"
    return sorted(p.stem.removeprefix("humanoid3d_") for p in folder.glob("humanoid3d_*.txt"))


@dataclass(frozen=True)
class ClipPose:
    """Pose of the clip at one instant, canonical axes, z up."""

    root_pos_world: np.ndarray  # (3,) pelvis [m], character scale
    local_quats: dict[str, np.ndarray]  # canonical joint -> local rotation (PELVIS: world orientation)


class DeepMimicClip:
    def __init__(self, frames: np.ndarray, loop: bool, name: str = "clip"):
        self.name = name
        self.loop = loop
        self.dt = frames[:-1, 0] if len(frames) > 1 else np.array([1.0])
        self.times = np.concatenate([[0.0], np.cumsum(self.dt)])[: len(frames)]
        self.duration_s = float(self.times[-1])
        self.root_pos = np.array([Q_WORLD_MODEL_MATRIX @ f[1:4] for f in frames])
        self.root_quat = np.array([canonical_quat_from_model(rot.normalize(f[4:8])) for f in frames])
        self.joints: dict[str, np.ndarray] = {}
        col = 8
        for name_, kind, width in _CLIP_LAYOUT:
            if kind == "ball":
                self.joints[name_] = np.array([canonical_quat_from_model(rot.normalize(f[col:col + 4]))
                                               for f in frames])
            else:
                self.joints[name_] = np.array(
                    [rot.quat_from_axis_angle(HINGE_AXIS_CANONICAL, float(f[col])) for f in frames])
            col += width
        # Per-cycle drift of a looping clip: position and heading change from the first to the last frame.
        self.cycle_offset = self.root_pos[-1] - self.root_pos[0]
        self.cycle_offset[2] = 0.0
        self.cycle_yaw = rot.yaw_from_quat(self.root_quat[-1]) - rot.yaw_from_quat(self.root_quat[0])
        # _drift_m[k]: the root's travel over the first k cycles, each cycle's offset turned by the heading the
        # cycles before it gained (Σ_{j<k} R_z(j·yaw) offset), extended as later cycles are asked for: the work of
        # a run grows with its number of cycles, not with that number squared.
        self._drift_m: list[np.ndarray] = [np.zeros(3)]

    @classmethod
    def load(cls, path: str | Path) -> DeepMimicClip:
        p = Path(path)
        data = read_json_file(p, "DeepMimic clip")
        if not isinstance(data, dict) or not isinstance(data.get("Frames"), list) or not data["Frames"]:
            raise SourceError(f"DeepMimic clip {p} has no 'Frames' list")
        try:
            frames = np.array(data["Frames"], dtype=float)
        except (TypeError, ValueError):
            raise SourceError(f"DeepMimic clip {p}: frames must be lists of {FRAME_WIDTH} numbers") from None
        if frames.ndim != 2 or frames.shape[1] != FRAME_WIDTH:
            raise SourceError(
                f"DeepMimic clip {p}: each frame must have {FRAME_WIDTH} numbers, got shape {frames.shape}")
        if not np.all(np.isfinite(frames)):
            raise SourceError(f"DeepMimic clip {p} contains NaN or infinite values")
        if len(frames) > 1 and np.any(frames[:-1, 0] <= 0):
            raise SourceError(f"DeepMimic clip {p}: frame durations must be > 0 s")
        for k, dt in enumerate(frames[:-1, 0]):
            if why := frame_interval_problem(float(dt)):
                raise SourceError(f"DeepMimic clip {p}: frame {k}: {why}")
        if why := distance_problem(frames[:, 1:4], frames[0, 1:4]):
            raise SourceError(f"DeepMimic clip {p}: root: {why}")
        return cls(frames, loop=data.get("Loop", "none") == "wrap", name=p.stem.removeprefix("humanoid3d_"))

    @classmethod
    def builtin(cls, name: str) -> DeepMimicClip:
        path = pybullet_clip_path(name)
        if not path.exists():
            raise SourceError(f"unknown clip '{name}'; expected one of {', '.join(builtin_clip_names())}")
        return cls.load(path)

    def _drift(self, cycles: int) -> np.ndarray:
        """(3,) the root's travel over the first ``cycles`` cycles of a looping clip [m]."""
        drift = self._drift_m
        while len(drift) <= cycles:
            k = len(drift) - 1
            drift.append(drift[k] + rot.matrix_from_quat(rot.quat_from_yaw(k * self.cycle_yaw)) @ self.cycle_offset)
        return drift[cycles]

    def pose_at(self, t_s: float) -> ClipPose:
        """Pose at clip time ``t_s`` [s]; a looping clip repeats with its per-cycle drift, others hold the end."""
        cycle = 0
        if self.loop and self.duration_s > 0:
            cycle = math.floor(t_s / self.duration_s)
            t_s -= cycle * self.duration_s
        t_s = min(max(t_s, 0.0), self.duration_s)
        i = int(np.searchsorted(self.times, t_s, side="right") - 1)
        i = min(max(i, 0), len(self.times) - 1)
        j = min(i + 1, len(self.times) - 1)
        span = self.times[j] - self.times[i]
        a = 0.0 if span <= 0 else (t_s - self.times[i]) / span
        root = (1 - a) * self.root_pos[i] + a * self.root_pos[j]
        q_root = rot.slerp(self.root_quat[i], self.root_quat[j], a)
        quats = {n: rot.slerp(v[i], v[j], a) for n, v in self.joints.items()}
        if cycle:
            q_cycle = rot.quat_from_yaw(cycle * self.cycle_yaw)
            R = rot.matrix_from_quat(q_cycle)
            start = self.root_pos[0].copy()
            start[2] = 0.0
            root = start + self._drift(cycle) + R @ (root - start)
            q_root = rot.multiply(q_cycle, q_root)
        quats["PELVIS"] = q_root
        return ClipPose(root, quats)


Q_WORLD_MODEL_MATRIX = rot.matrix_from_quat(Q_WORLD_MODEL)

"""Recorded operator tracks on the canonical skeleton, and canonical orientations from any skeleton's rest pose.

A :class:`TrackPerformer` holds a recording as arrays (times, joint positions, canonical orientations, confidences)
and answers ``frame_at(t)`` by interpolation (linear for positions, normalised lerp on the shorter arc for
quaternions), so that any recorded source can pass through the sensor model (resampling, noise, dropouts).

Other skeletons (BVH files, VMC streams) state their joint orientations relative to their own rest pose, whose
segments point in directions of their own (a T-pose has arms out sideways, ours hang down). :func:`rest_corrections`
finds, from the rest-pose joint positions, the canonical orientation of each segment in that rest pose; a segment's
canonical orientation at any time is then ``R_world(t) ⊗ q_rest`` (``R_world`` its world rotation relative to the
rest pose, in our world axes).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame

# Canonical segment -> (distal joint giving its direction, that direction in the canonical rest pose, facing +x).
SEGMENT_DIRECTIONS: dict[str, tuple[str, tuple[float, float, float]]] = {
    "SPINE_CHEST": ("NECK", (0.0, 0.0, 1.0)),
    "NECK": ("HEAD", (0.0, 0.0, 1.0)),
    "HIP_LEFT": ("KNEE_LEFT", (0.0, 0.0, -1.0)),
    "HIP_RIGHT": ("KNEE_RIGHT", (0.0, 0.0, -1.0)),
    "KNEE_LEFT": ("ANKLE_LEFT", (0.0, 0.0, -1.0)),
    "KNEE_RIGHT": ("ANKLE_RIGHT", (0.0, 0.0, -1.0)),
    "ANKLE_LEFT": ("FOOT_LEFT", (1.0, 0.0, 0.0)),  # horizontal: a flat foot, whatever the toe joint's height
    "ANKLE_RIGHT": ("FOOT_RIGHT", (1.0, 0.0, 0.0)),
    "SHOULDER_LEFT": ("ELBOW_LEFT", (0.0, 0.0, -1.0)),
    "SHOULDER_RIGHT": ("ELBOW_RIGHT", (0.0, 0.0, -1.0)),
    "ELBOW_LEFT": ("WRIST_LEFT", (0.0, 0.0, -1.0)),
    "ELBOW_RIGHT": ("WRIST_RIGHT", (0.0, 0.0, -1.0)),
}
_HORIZONTAL = {"ANKLE_LEFT", "ANKLE_RIGHT"}
# Canonical joints a skeleton must provide (positions) to drive the character.
REQUIRED_JOINTS: tuple[str, ...] = (
    "PELVIS", "SPINE_CHEST", "NECK", "HEAD", "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "FOOT_LEFT", "HIP_RIGHT",
    "KNEE_RIGHT", "ANKLE_RIGHT", "FOOT_RIGHT", "SHOULDER_LEFT", "ELBOW_LEFT", "WRIST_LEFT", "SHOULDER_RIGHT",
    "ELBOW_RIGHT", "WRIST_RIGHT",
)
# Joints a skeleton may lack, filled from a neighbour (position and orientation) with full confidence.
FILL_FROM: dict[str, str] = {
    "SPINE_NAVEL": "PELVIS", "CLAVICLE_LEFT": "SPINE_CHEST", "CLAVICLE_RIGHT": "SPINE_CHEST",
    "HAND_LEFT": "WRIST_LEFT", "HANDTIP_LEFT": "WRIST_LEFT", "THUMB_LEFT": "WRIST_LEFT",
    "HAND_RIGHT": "WRIST_RIGHT", "HANDTIP_RIGHT": "WRIST_RIGHT", "THUMB_RIGHT": "WRIST_RIGHT",
    "NOSE": "HEAD", "EYE_LEFT": "HEAD", "EAR_LEFT": "HEAD", "EYE_RIGHT": "HEAD", "EAR_RIGHT": "HEAD",
}
# Joints without a segment of their own take the orientation of this one.
ORIENTATION_FROM: dict[str, str] = {
    "HEAD": "NECK", "FOOT_LEFT": "ANKLE_LEFT", "FOOT_RIGHT": "ANKLE_RIGHT", "WRIST_LEFT": "ELBOW_LEFT",
    "WRIST_RIGHT": "ELBOW_RIGHT", **FILL_FROM,
}


WINTER_ANKLE_PER_HIP_TO_ANKLE = 0.039 / (0.530 - 0.039)  # Winter (2009) Table 4.1: ankle, hip heights / stature


def rest_facing_yaw(rest_pos_world: dict[str, np.ndarray]) -> float:
    """Heading [rad] of a rest pose, z up: forward = left × up, left from the right hip to the left hip."""
    left = rest_pos_world["HIP_LEFT"] - rest_pos_world["HIP_RIGHT"]
    forward = rot.cross(left, np.array([0.0, 0.0, 1.0]))
    if np.linalg.norm(forward[:2]) < 1e-9:
        raise SourceError("rest pose has coincident hips; cannot tell which way it faces")
    return float(np.arctan2(forward[1], forward[0]))


def rest_corrections(rest_pos_world: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Canonical orientation (wxyz) of each segment of a skeleton in its rest pose, from joint positions [m].

    The segment's twist at rest is taken as none relative to the body's facing (true of T- and A-poses).
    """
    q_yaw = rot.quat_from_yaw(rest_facing_yaw(rest_pos_world))
    out = {"PELVIS": q_yaw}
    for seg, (distal, d0) in SEGMENT_DIRECTIONS.items():
        d_world = rest_pos_world[distal] - rest_pos_world[seg]
        if seg in _HORIZONTAL:
            d_world = np.array([d_world[0], d_world[1], 0.0])
        d_body = rot.rotate(rot.conjugate(q_yaw), d_world)
        if np.linalg.norm(d_body) < 1e-9:
            raise SourceError(f"rest pose: joints {seg} and {distal} coincide; cannot orient the segment")
        out[seg] = rot.multiply(q_yaw, rot.rotation_between(np.array(d0), d_body))
    return out


def fill_canonical(pos: np.ndarray, quat: np.ndarray, conf: np.ndarray) -> None:
    """In place, on (T, 32, ...) arrays: joints the skeleton lacks take their neighbour's values (FILL_FROM), and
    segment-less joints their parent segment's orientation (ORIENTATION_FROM)."""
    for joint, src in FILL_FROM.items():
        i, j = JOINT_INDEX[joint], JOINT_INDEX[src]
        if not np.any(conf[:, i] > 0):
            pos[:, i] = pos[:, j]
            conf[:, i] = conf[:, j]
    for joint, src in ORIENTATION_FROM.items():
        quat[:, JOINT_INDEX[joint]] = quat[:, JOINT_INDEX[src]]


def place_on_floor(pos: np.ndarray) -> None:
    """In place, on (T, 32, 3) [m]: shift z so that the lowest ankle of the recording sits at Winter's ankle
    height, 0.039 of stature = 0.079 of the hip-to-ankle length (median over frames, both legs)."""
    hips = pos[:, [JOINT_INDEX["HIP_LEFT"], JOINT_INDEX["HIP_RIGHT"]]]
    ankles = pos[:, [JOINT_INDEX["ANKLE_LEFT"], JOINT_INDEX["ANKLE_RIGHT"]]]
    leg = float(np.median(np.linalg.norm(hips - ankles, axis=-1)))
    pos[:, :, 2] += WINTER_ANKLE_PER_HIP_TO_ANKLE * leg - float(ankles[:, :, 2].min())


def batch_nlerp(q0: np.ndarray, q1: np.ndarray, a: float) -> np.ndarray:
    """Normalised lerp of rows of (n, 4) quaternions along the shorter arc."""
    sign = np.where(np.sum(q0 * q1, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    q = (1 - a) * q0 + a * sign * q1
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


class TrackPerformer:
    """A recording on the canonical skeleton; ``frame_at(t)`` interpolates it (t in [s] from its start)."""

    def __init__(self, times_s: np.ndarray, pos_world: np.ndarray, quat_wxyz: np.ndarray, conf: np.ndarray,
                 name: str = "recording"):
        if len(times_s) == 0:
            raise SourceError(f"{name}: no frames")
        if pos_world.shape != (len(times_s), N_JOINTS, 3) or quat_wxyz.shape != (len(times_s), N_JOINTS, 4):
            raise SourceError(f"{name}: expected ({len(times_s)}, {N_JOINTS}, 3|4) joint arrays")
        self.name = name
        self.times_s = np.asarray(times_s, dtype=float)
        self.pos_world = pos_world
        self.quat_wxyz = quat_wxyz
        self.conf = conf
        self.duration_s = float(self.times_s[-1] - self.times_s[0])
        self.rate_hz = (len(self.times_s) - 1) / self.duration_s if self.duration_s > 0 else 0.0

    def frame_at(self, t_s: float) -> OperatorFrame:
        ts = self.times_s
        t = min(max(t_s + ts[0], ts[0]), ts[-1])
        i = int(np.clip(np.searchsorted(ts, t, side="right") - 1, 0, len(ts) - 1))
        j = min(i + 1, len(ts) - 1)
        span = ts[j] - ts[i]
        a = 0.0 if span <= 0 else float((t - ts[i]) / span)
        pos = (1 - a) * self.pos_world[i] + a * self.pos_world[j]
        quat = batch_nlerp(self.quat_wxyz[i], self.quat_wxyz[j], a)
        conf = np.minimum(self.conf[i], self.conf[j]) if a > 0 else self.conf[i].copy()
        return OperatorFrame(t_s, pos, quat, conf)

    def frames(self) -> list[OperatorFrame]:
        """The recorded frames themselves, at their own instants (time from the first frame)."""
        t0 = self.times_s[0]
        return [OperatorFrame(float(t - t0), self.pos_world[k].copy(), self.quat_wxyz[k].copy(), self.conf[k].copy())
                for k, t in enumerate(self.times_s)]

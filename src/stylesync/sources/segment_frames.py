"""Canonical segment orientations from joint positions alone (sources that give positions only, or orientations in
conventions we do not trust: MediaPipe world landmarks, Azure Kinect JSON from other tools).

Each segment's frame is built from its direction and a second vector: the pelvis from its hips and spine, the
torso from its spine and shoulders, a limb from its bone and the plane of its middle joint (the knee or elbow
hinge axis, falling back to the body's left axis when the limb is straight), the foot from ankle-to-toe and world
up. The frame's columns are the canonical body axes (x forward, y left, z up in the rest pose), so the result is
the canonical orientation of sources/frame.py. Works on (T, 32, 3) arrays at once.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS
from stylesync.sources.skeleton_tracks import ORIENTATION_FROM

_STRAIGHT_LIMB = 0.15  # |sin| of the middle-joint angle below which a limb counts as straight


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-12)


def _frame_quats(z_axis: np.ndarray, y_hint: np.ndarray) -> np.ndarray:
    """Quaternions (T, 4) of frames whose z is ``z_axis`` and whose y is ``y_hint`` made orthogonal to it."""
    z = _unit(z_axis)
    y = _unit(y_hint - np.sum(y_hint * z, axis=-1, keepdims=True) * z)
    x = rot.cross(y, z)
    R = np.stack([x, y, z], axis=-1)  # columns
    return np.array([rot.quat_from_matrix(m) for m in R])


def _frame_quats_xz(x_axis: np.ndarray, z_hint: np.ndarray) -> np.ndarray:
    """Frames whose x is ``x_axis`` and whose z is ``z_hint`` made orthogonal to it."""
    x = _unit(x_axis)
    z = _unit(z_hint - np.sum(z_hint * x, axis=-1, keepdims=True) * x)
    y = rot.cross(z, x)
    R = np.stack([x, y, z], axis=-1)
    return np.array([rot.quat_from_matrix(m) for m in R])


def orientations_from_positions(pos: np.ndarray) -> dict[str, np.ndarray]:
    """Canonical segment orientations (T, 4) per canonical joint, from joint positions (T, 32, 3) [m]."""
    P = {n: pos[:, i] for n, i in JOINT_INDEX.items()}
    up = np.array([0.0, 0.0, 1.0])
    pelvis_left = P["HIP_LEFT"] - P["HIP_RIGHT"]
    spine = P["SPINE_CHEST"] - P["PELVIS"]
    out = {"PELVIS": _frame_quats(np.where(np.linalg.norm(spine, axis=-1, keepdims=True) > 1e-6, spine, up),
                                  pelvis_left)}
    torso_left = P["SHOULDER_LEFT"] - P["SHOULDER_RIGHT"]
    out["SPINE_CHEST"] = _frame_quats(P["NECK"] - P["SPINE_CHEST"], torso_left)
    out["NECK"] = _frame_quats(P["HEAD"] - P["NECK"], torso_left)
    for side in ("LEFT", "RIGHT"):
        for top, mid, end, left_ref, hinge_sign in (("HIP", "KNEE", "ANKLE", pelvis_left, 1.0),
                                                     ("SHOULDER", "ELBOW", "WRIST", torso_left, -1.0)):
            a, b, c = P[f"{top}_{side}"], P[f"{mid}_{side}"], P[f"{end}_{side}"]
            upper, lower = a - b, c - b
            # Hinge axis: the knee bends backwards about +y (left), the elbow forwards: sign from the model axes.
            hinge = hinge_sign * rot.cross(lower, upper)
            s = np.linalg.norm(hinge, axis=-1) / np.maximum(
                np.linalg.norm(upper, axis=-1) * np.linalg.norm(lower, axis=-1), 1e-12)
            y_hint = np.where((s > _STRAIGHT_LIMB)[:, None], hinge, left_ref)
            out[f"{top}_{side}"] = _frame_quats(a - b, y_hint)
            out[f"{mid}_{side}"] = _frame_quats(b - c, y_hint)
        # The foot: x along ankle-to-toe, z towards world up. A flat foot whose toe joint sits below the ankle reads
        # as pitched toe-down by that angle; only the foot's heading (twist T) is used downstream.
        out[f"ANKLE_{side}"] = _frame_quats_xz(P[f"FOOT_{side}"] - P[f"ANKLE_{side}"], np.broadcast_to(up, a.shape))
    return out


def canonical_quats_from_positions(pos: np.ndarray) -> np.ndarray:
    """Orientations (T, 32, 4) of every canonical joint from positions (T, 32, 3) [m]; joints without a segment
    take their neighbour's (``ORIENTATION_FROM``)."""
    quat = np.tile(rot.IDENTITY_WXYZ, (len(pos), N_JOINTS, 1))
    for name, q in orientations_from_positions(pos).items():
        quat[:, JOINT_INDEX[name]] = q
    for joint, src in ORIENTATION_FROM.items():
        quat[:, JOINT_INDEX[joint]] = quat[:, JOINT_INDEX[src]]
    return quat

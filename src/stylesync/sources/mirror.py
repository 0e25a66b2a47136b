"""The operator's mirror image: his right side drives the character's left (``OperatorConfig.mirror``).

A person facing the character on a screen expects it to move like his reflection: he raises his right hand and the
hand on the same side of the screen, the character's left, goes up. Every frame is reflected in the world's x-z
plane (the vertical plane along his forward axis x) and its left and right joints are swapped:

    x'_j = M x_{σ(j)},    R'_j = M R_{σ(j)} M,    M = diag(1, -1, 1)

for every joint j, σ swapping ``*_LEFT`` and ``*_RIGHT``. A segment orientation R (canonical: the identity is the
mirror-symmetric rest pose, sources/frame.py) reflected on both sides stays a rotation; for w, x, y, z it is
(w, -x, y, -z). The COM and a point cloud are reflected like joints. Applied twice it gives the frame back.

The reflected frames are a valid motion of the same person (the character walks off on the other foot, turns the
other way): the development suite run on them (``stylesync bench --suite dev --mirror``) is a second sample of
what users bring, with every left-right asymmetry of the pipeline turned round.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from stylesync.sources.base import OperatorSource
from stylesync.sources.frame import JOINT_INDEX, K4ABT_JOINTS, OperatorFrame


def _swap_sides(name: str) -> str:
    if name.endswith("_LEFT"):
        return name.removesuffix("_LEFT") + "_RIGHT"
    if name.endswith("_RIGHT"):
        return name.removesuffix("_RIGHT") + "_LEFT"
    return name


# SIDE_SWAP[j]: the joint whose values joint j takes in the mirror image (its other side's, or its own).
SIDE_SWAP = np.array([JOINT_INDEX[_swap_sides(n)] for n in K4ABT_JOINTS])
_REFLECT_POS = np.array([1.0, -1.0, 1.0])  # M, the reflection in the x-z plane
_REFLECT_QUAT_WXYZ = np.array([1.0, -1.0, 1.0, -1.0])  # M R M as a quaternion: (w, -x, y, -z)


def mirror_frame(frame: OperatorFrame) -> OperatorFrame:
    """The mirror image of ``frame`` (a new frame; ``frame`` is not changed): positions [m] and segment
    orientations (w, x, y, z) reflected in the x-z plane, left and right joints swapped with their confidences."""
    return dataclasses.replace(
        frame,
        joint_pos_world=frame.joint_pos_world[SIDE_SWAP] * _REFLECT_POS,
        joint_quat_wxyz=frame.joint_quat_wxyz[SIDE_SWAP] * _REFLECT_QUAT_WXYZ,
        confidence=np.asarray(frame.confidence)[SIDE_SWAP].copy(),
        com_world=None if frame.com_world is None else np.asarray(frame.com_world) * _REFLECT_POS,
        point_cloud_world=(None if frame.point_cloud_world is None
                           else np.asarray(frame.point_cloud_world) * _REFLECT_POS),
        extras=dict(frame.extras),
    )


class MirroredSource(OperatorSource):
    """``source``'s frames as their mirror images (:func:`mirror_frame`). Everything else (a recording's start in
    motion, a live stream's first-frame wait, its rejection counts, closing it) is the wrapped source's."""

    def __init__(self, source: OperatorSource):
        self.source = source

    def poll(self, now_s: float) -> list[OperatorFrame]:
        return [mirror_frame(f) for f in self.source.poll(now_s)]

    def close(self) -> None:
        self.source.close()

    @property
    def rejected_frames(self) -> int:  # type: ignore[override]
        return self.source.rejected_frames

    def __getattr__(self, name: str) -> Any:
        # Only reached for what this class does not define: the wrapped source's own attributes.
        if name == "source":
            raise AttributeError(name)
        return getattr(self.source, name)

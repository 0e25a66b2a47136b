"""One person followed through a video with several people in it.

MediaPipe Pose finds one person per image, the most prominent; in a scene with several people it may change from
one frame to the next, and the operator would jump from one body to another. The follower therefore looks for the
person where he was last seen. The first person found in the whole image is the one followed. After that, each
image is cropped to a square window around his last hip position (image pixels), and the pose model runs on the
crop:

    half-side = torso · (WINDOW_TORSOS + TRAVEL_TORSOS_PER_S · Δt)

Here ``torso`` is his last hip-to-shoulder length in pixels and Δt the time since he was last seen [s]. The window
holds his whole body: a standing person is about 3.3 torso lengths tall, his hips in the middle. It also holds how
far he can have walked since he was last seen. It grows while he is not found, so he is found again after he has
been hidden. World landmarks (metres, centred on the hips) do not depend on the crop; image landmarks are mapped
back to the whole image. A pose whose hips lie outside the window (landmarks guessed beyond the image, as for a
person who walks out of it) is not his, and neither is one whose torso is more than twice or less than half the one
he had less than a second before.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

WINDOW_TORSOS = 2.5  # half the window's side around the hips, in torso lengths
TRAVEL_TORSOS_PER_S = 3.0  # a walking person moves about 3 torso lengths a second (1.4 m/s, 0.45 m torso)
MIN_HALF_PX = 48  # the window is never smaller than this (half its side) [px]
MAX_SIZE_CHANGE = 2.0  # the followed person's torso in the image grows or shrinks at most by this factor ...
SIZE_MEMORY_S = 1.0  # ... within this time [s]; after longer, whoever is found in the window is taken
_HIPS, _SHOULDERS = (23, 24), (11, 12)  # BlazePose landmarks


@dataclass
class Followed:
    """The followed person in one image."""

    world_xyz: np.ndarray  # (33, 3) world landmarks (camera axes, m, origin between the hips)
    visibility: np.ndarray  # (33,)
    hip_px: np.ndarray  # (2,) hip centre in the whole image [px]
    torso_px: float  # hip-to-shoulder length in the image [px]


class PersonFollower:
    """Runs a MediaPipe Pose instance (``pose``: ``process(rgb) -> result``) on the window where the followed person
    was last seen (:mod:`person_follower`)."""

    def __init__(self, pose: Any):
        self.pose = pose
        self.hip_px: np.ndarray | None = None
        self.torso_px = 0.0
        self.last_seen_s = 0.0

    def window(self, shape: tuple[int, ...], t_s: float) -> tuple[int, int, int, int]:
        """(x0, y0, x1, y1) of the window searched at time ``t_s`` in an image of ``shape`` (rows, columns, ...)."""
        rows, cols = shape[0], shape[1]
        if self.hip_px is None:
            return 0, 0, cols, rows
        half = max(self.torso_px * (WINDOW_TORSOS + TRAVEL_TORSOS_PER_S * max(t_s - self.last_seen_s, 0.0)),
                   MIN_HALF_PX)
        x, y = self.hip_px
        x0, x1 = int(max(x - half, 0)), int(min(x + half, cols))
        y0, y1 = int(max(y - half, 0)), int(min(y + half, rows))
        if x1 - x0 < 2 or y1 - y0 < 2:  # he left the image: search all of it
            return 0, 0, cols, rows
        return x0, y0, x1, y1

    def find(self, rgb: np.ndarray, t_s: float) -> Followed | None:
        """The followed person in an RGB image taken at ``t_s`` [s], or None where he is not found."""
        x0, y0, x1, y1 = self.window(rgb.shape, t_s)
        crop = np.ascontiguousarray(rgb[y0:y1, x0:x1])
        res = self.pose.process(crop)
        if res.pose_world_landmarks is None or res.pose_landmarks is None:
            return None
        image = np.array([[q.x, q.y] for q in res.pose_landmarks.landmark]) * [x1 - x0, y1 - y0] + [x0, y0]
        hip = image[list(_HIPS)].mean(axis=0)
        torso = float(np.linalg.norm(image[list(_SHOULDERS)].mean(axis=0) - hip))
        if not (x0 <= hip[0] < x1 and y0 <= hip[1] < y1):
            return None  # landmarks guessed beyond the image: a person leaving it
        recent = self.hip_px is not None and t_s - self.last_seen_s <= SIZE_MEMORY_S
        if recent and not 1 / MAX_SIZE_CHANGE <= torso / self.torso_px <= MAX_SIZE_CHANGE:
            return None  # not the size he had a moment ago
        self.hip_px, self.torso_px, self.last_seen_s = hip, max(torso, 1.0), t_s
        world = res.pose_world_landmarks.landmark
        return Followed(np.array([[q.x, q.y, q.z] for q in world]), np.array([q.visibility for q in world]),
                        hip, torso)

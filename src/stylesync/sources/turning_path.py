"""A performer's path bent into a turn: the built-in clips walk straight, people turn.

The performer's pose at time t is turned about the vertical through his pelvis by the heading θ(t) = ω (t - t₀)
(zero before t₀), and his pelvis is moved along the path whose velocity over the ground is his own turned by θ:

    p'(t) = p(t₀) + ∫ R(θ(s)) ṗ(s) ds,    x'_j(t) = p'(t) + R(θ(t)) (x_j(t) - p(t)),    q'_j(t) = q_yaw(θ(t)) q_j(t)

for every joint j (positions x, segment orientations q, the COM like a joint), p the pelvis over the ground and R
the rotation about z. A straight walk at speed v becomes a circle of radius v / ω, its steps, timing and style as
recorded. A planted foot at a horizontal distance d from the pelvis slides at ω d (0.6 rad/s and 0.1 m: 6 cm/s),
as a person's pivoting foot does. The path is integrated once on a grid (``dt_s``) up to ``end_s`` and interpolated
linearly in between (the pose function is asked once per grid point: about 0.3 ms a call for the built-in
performer); a pose asked for after ``end_s`` takes the grid's last pelvis point and path point.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from stylesync import rotations as rot
from stylesync.sources.frame import JOINT_INDEX, OperatorFrame

_PELVIS = JOINT_INDEX["PELVIS"]


class TurningPath:
    """``pose_at`` (time [s] -> OperatorFrame, world frame, z up) turned at ``rate_rad_s`` (+: counter-clockwise
    seen from above) from ``start_s`` on; callable as a performer's pose function."""

    def __init__(self, pose_at: Callable[[float], OperatorFrame], rate_rad_s: float, start_s: float, end_s: float,
                 dt_s: float = 0.01):
        self.pose_at = pose_at
        self.rate_rad_s = rate_rad_s
        self.start_s = start_s
        self.times_s = np.arange(0.0, end_s + dt_s, dt_s)  # (n,) the integration grid [s]
        pelvis = np.array([pose_at(float(t)).joint_pos_world[_PELVIS] for t in self.times_s])  # (n, 3) [m]
        self._pelvis_xy = pelvis[:, :2]
        heading_rad = rate_rad_s * np.clip(self.times_s - start_s, 0.0, None)  # (n,) θ [rad]
        c, s = np.cos(heading_rad), np.sin(heading_rad)
        step = np.diff(self._pelvis_xy, axis=0, prepend=self._pelvis_xy[:1])  # (n, 2) [m]
        turned = np.stack([c * step[:, 0] - s * step[:, 1], s * step[:, 0] + c * step[:, 1]], axis=1)
        self.path_xy = self._pelvis_xy[0] + np.cumsum(turned, axis=0)  # (n, 2) p' [m]

    def __call__(self, t_s: float) -> OperatorFrame:
        f = self.pose_at(t_s)
        theta = self.rate_rad_s * max(t_s - self.start_s, 0.0)  # θ(t) [rad]
        if theta == 0.0:
            return f
        q_yaw = rot.quat_from_yaw(theta)
        R = rot.matrix_from_quat(q_yaw)
        # About his pelvis over the ground (its height kept), then onto the turned path, both on the grid
        about = np.array([*self._on_grid(self._pelvis_xy, t_s), 0.0])
        shift = np.array([*self._on_grid(self.path_xy, t_s), 0.0])
        positions = (f.joint_pos_world - about) @ R.T + shift
        com = None if f.com_world is None else (f.com_world - about) @ R.T + shift
        quats = rot.batch_multiply(np.broadcast_to(q_yaw, f.joint_quat_wxyz.shape), f.joint_quat_wxyz)
        cloud = None if f.point_cloud_world is None else (f.point_cloud_world - about) @ R.T + shift
        return dataclasses.replace(f, joint_pos_world=positions, joint_quat_wxyz=quats, com_world=com,
                                   point_cloud_world=cloud)

    def _on_grid(self, xy: np.ndarray, t_s: float) -> list[float]:
        """(2,) the grid's (n, 2) ``xy`` interpolated linearly at ``t_s`` [s] (held beyond its ends)."""
        return [float(np.interp(t_s, self.times_s, xy[:, 0])), float(np.interp(t_s, self.times_s, xy[:, 1]))]

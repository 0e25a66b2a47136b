"""A Kinect-like sensor model that any recorded source can pass through.

Samples the recorded motion at the sensor rate (16 Hz, Sec. 7.1) at slightly jittered instants, adds Gaussian
noise to joint positions and orientations, and (optionally) drops joints now and then, marking them with
confidence 0. A fixed seed makes the stream reproducible.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ClockConfig, OperatorConfig
from stylesync.sources.frame import OperatorFrame


@dataclass(frozen=True)
class SensorModel:
    rate_hz: float = 16.0  # Sec. 7.1, Kinect update rate
    position_noise_m: float = 0.005
    orientation_noise_rad: float = 0.02
    timestamp_jitter_s: float = 0.004
    dropout_probability: float = 0.0  # per joint and frame
    seed: int = 0

    @classmethod
    def kinect(cls, operator: OperatorConfig, clocks: ClockConfig, seed: int,
               dropout_probability: float = 0.0) -> SensorModel:
        """The Kinect-like sensor of the operator configuration, at the mocap rate."""
        return cls(rate_hz=clocks.mocap_hz, position_noise_m=operator.position_noise_m,
                   orientation_noise_rad=operator.orientation_noise_rad,
                   timestamp_jitter_s=operator.timestamp_jitter_s, dropout_probability=dropout_probability, seed=seed)

    def sample(self, pose_at: Callable[[float], OperatorFrame], duration_s: float) -> list[OperatorFrame]:
        """Frames at ``rate_hz`` over ``[0, duration_s]``; ``pose_at(t)`` gives the noise-free frame at t [s]."""
        rng = np.random.default_rng(self.seed)
        n = int(np.floor(duration_s * self.rate_hz)) + 1
        frames: list[OperatorFrame] = []
        for k in range(n):
            t_nominal = k / self.rate_hz
            t = max(0.0, t_nominal + rng.normal(0.0, self.timestamp_jitter_s)) if k else 0.0
            f = pose_at(t)
            pos = f.joint_pos_world + rng.normal(0.0, self.position_noise_m, f.joint_pos_world.shape)
            quat = f.joint_quat_wxyz.copy()
            for i in range(len(quat)):
                noise = rng.normal(0.0, self.orientation_noise_rad, 3)
                quat[i] = rot.normalize(rot.multiply(quat[i], rot.quat_from_rotvec(noise)))
            conf = f.confidence.copy()
            if self.dropout_probability > 0:
                conf[rng.random(len(conf)) < self.dropout_probability] = 0.0
            # The frame is stamped with its nominal sensor time: jitter shows in the content, as with a camera.
            frames.append(OperatorFrame(t_nominal, pos, quat, conf, com_world=f.com_world))
        return frames

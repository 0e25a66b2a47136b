"""The built-in operator: a real recorded human clip played by a human-scale skeleton through a Kinect-like
sensor, so that ``stylesync demo`` runs with no camera and no download.

The clip (pybullet_data ``humanoid3d_<name>.txt``, from DeepMimic's motion capture) provides joint rotations; the
:class:`HumanModel` gives the operator its own size and mass distribution (Table 2 human column), its pelvis
path is scaled by the ratio of its leg length to the clip character's so that its feet do not slide, and the
:class:`SensorModel` samples it at 16 Hz with noise and jitter from a fixed seed. The operator first stands for
``standing_lead_in_s`` in the clip's first pose. With ``turn_rate_rad_s`` his path is bent into a turn after the
lead-in (turning_path.py).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ClockConfig, OperatorConfig
from stylesync.sources.base import RecordedSource
from stylesync.sources.deepmimic_clip import CLIP_CHARACTER_LEG_LENGTH_M, DeepMimicClip
from stylesync.sources.frame import OperatorFrame
from stylesync.sources.human_model import HumanModel
from stylesync.sources.sensor_model import SensorModel
from stylesync.sources.turning_path import TurningPath

STAND_CLIP = "stand"  # an operator standing still, for balance checks
_RAMP_GRID_HZ = 240.0  # grid of the ramped pelvis path's integral


class ClipPerformer:
    """Noise-free operator frames of a human skeleton playing a clip."""

    def __init__(self, clip: DeepMimicClip | None, human: HumanModel, lead_in_s: float = 0.0,
                 blend_s: float = 0.5, start_ramp_s: float = 0.0, speed: float = 1.0):
        self.clip = clip
        self.speed = speed  # the clip's time runs this many times faster than the run's after the lead-in [-]
        self.human = human
        self.lead_in_s = lead_in_s
        self.leg_ratio = (human.hip_height_m) / CLIP_CHARACTER_LEG_LENGTH_M
        self.start_ramp_s = start_ramp_s if clip is not None and clip.loop else 0.0
        self.blend_s = 0.0 if self.start_ramp_s > 0 else min(blend_s, lead_in_s)
        self._stand_root, self._stand_quats = self._standing()
        if self.start_ramp_s > 0:  # ∫_0^s (p_clip(s') - p_clip(0)) ds' on a fine grid, for the ramped pelvis path
            self._ramp_t = np.linspace(0.0, self.start_ramp_s, int(self.start_ramp_s * _RAMP_GRID_HZ) + 2)
            self._clip_root_0 = self._clip_root(0.0)
            p = np.array([self._clip_root(t) for t in self._ramp_t]) - self._clip_root_0
            steps = 0.5 * (p[1:] + p[:-1]) * np.diff(self._ramp_t)[:, None]
            self._ramp_integral = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])

    def _clip_root(self, t_s: float) -> np.ndarray:
        assert self.clip is not None
        return self.clip.pose_at(t_s).root_pos_world * self.leg_ratio

    def _ramped(self, u_s: float) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Pelvis position and joint rotations ``u_s`` [s] into a looping clip started from standing (see the
        module): weight a = u / ramp; pelvis = p_0 + a (p(u) - p(0)) - (1/ramp) ∫_0^u (p - p(0)), which is
        p_0 + ∫_0^u a ṗ by parts."""
        assert self.clip is not None
        ramp = self.start_ramp_s
        a = min(u_s / ramp, 1.0)
        pose = self.clip.pose_at(u_s)
        integral = np.array([np.interp(min(u_s, ramp), self._ramp_t, self._ramp_integral[:, k]) for k in range(3)])
        root = self._stand_root + a * (pose.root_pos_world * self.leg_ratio - self._clip_root_0) - integral / ramp
        root[2] = (1 - a) * self._stand_root[2] + a * pose.root_pos_world[2] * self.leg_ratio
        stand = self._stand_quats
        return root, {k: rot.slerp(stand.get(k, rot.IDENTITY_WXYZ), q, a) for k, q in pose.local_quats.items()}

    def _standing(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Neutral standing pose where the clip starts, facing its first heading."""
        if self.clip is None:
            return np.array([0.0, 0.0, self.human.hip_height_m]), {}
        first = self.clip.pose_at(0.0)
        yaw = rot.yaw_from_quat(first.local_quats["PELVIS"])
        root = first.root_pos_world * self.leg_ratio
        return np.array([root[0], root[1], self.human.hip_height_m]), {"PELVIS": rot.quat_from_yaw(yaw)}

    def frame_at(self, t_s: float) -> OperatorFrame:
        stand_root, stand_quats = self._stand_root, self._stand_quats
        if self.clip is None or t_s < self.lead_in_s - self.blend_s:
            return self.human.frame_from_pose(t_s, stand_root, stand_quats)
        u_s = self.speed * (t_s - self.lead_in_s)  # the clip's time [s]
        if self.start_ramp_s > 0:
            return self.human.frame_from_pose(t_s, *self._ramped(u_s))
        pose = self.clip.pose_at(max(0.0, u_s))
        root = pose.root_pos_world * self.leg_ratio
        if t_s < self.lead_in_s:  # blend from standing into the clip's first pose
            a = 1.0 - (self.lead_in_s - t_s) / self.blend_s
            root = (1 - a) * stand_root + a * root
            quats = {k: rot.slerp(stand_quats.get(k, rot.IDENTITY_WXYZ), q, a) for k, q in pose.local_quats.items()}
            return self.human.frame_from_pose(t_s, root, quats)
        return self.human.frame_from_pose(t_s, root, pose.local_quats)


def sensed(pose_at: Callable[[float], OperatorFrame], operator: OperatorConfig, clocks: ClockConfig,
           duration_s: float, seed: int, name: str) -> RecordedSource:
    """A performer seen through the operator's Kinect-like sensor model, as a recorded source."""
    frames = SensorModel.kinect(operator, clocks, seed).sample(pose_at, duration_s)
    return RecordedSource(frames, name=name)


def builtin_operator(
    operator: OperatorConfig, clocks: ClockConfig, duration_s: float, seed: int
) -> tuple[RecordedSource, ClipPerformer]:
    clip = None if operator.clip == STAND_CLIP else DeepMimicClip.builtin(operator.clip)
    human = HumanModel(operator.height_m, operator.mass_kg)
    performer = ClipPerformer(clip, human, operator.standing_lead_in_s, start_ramp_s=operator.start_ramp_s,
                              speed=operator.playback_speed)
    pose_at: Callable[[float], OperatorFrame] = performer.frame_at
    if operator.turn_rate_rad_s != 0.0:
        pose_at = TurningPath(pose_at, operator.turn_rate_rad_s, operator.standing_lead_in_s, duration_s)
    return sensed(pose_at, operator, clocks, duration_s, seed, f"builtin:{operator.clip}"), performer


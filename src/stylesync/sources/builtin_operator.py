"""The built-in operator: a real recorded human clip played by a human-scale skeleton through a Kinect-like
sensor, so that ``stylesync demo`` runs with no camera and no download.

The clip (pybullet_data ``humanoid3d_<name>.txt``, from DeepMimic's motion capture) provides joint rotations; the
:class:`HumanModel` gives the operator its own size and mass distribution (Table 2 human column), its pelvis
path is scaled by the ratio of its leg length to the clip character's so that its feet do not slide, and the
:class:`SensorModel` samples it at 16 Hz with noise and jitter from a fixed seed. The operator first stands for
``standing_lead_in_s`` in the clip's first pose. With ``turn_rate_rad_s`` his path is bent into a turn after the
lead-in (turning_path.py).

A looping clip (a walk, a run, a spin) is mid-motion at every frame, so it cannot begin at its full pace from a
stand. Two starts (``OperatorConfig.start_ramp``):

* ``"rate"``: he stands for the lead-in in the clip's own pose at the phase where his feet are nearest the
  ground (a clip with no pose on both feet, a run, starts as with ``"blend"``), and the clip's time then runs at a
  rate that grows from 0 to 1 over ``start_ramp_s`` (clip time u = u_0 + τ² / (2 T) for τ < T, u_0 + τ - T / 2
  after). Every pose he takes is one of the clip's, so a foot that stands in the clip stands in the start too, and
  his heading turns along the clip's own path.
* ``"blend"`` (the default): he stands in a neutral pose and the clip's joint rotations are blended in from it over
  ``start_ramp_s`` (slerp, the shorter arc), the pelvis's velocity scaled by the same weight. His feet slide in
  that blend (the built-in walk's left foot 0.26 m forwards at 6 cm height, no step), and a clip that turns
  turns him the shorter way in one frame (125 degrees in dance_a) (docs/decisions.md, "The operator's heading
  where his trunk bends over"). Measured, the character does no better on the rate's start (docs/decisions.md,
  "A built-in clip's start at a growing rate").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from stylesync import rotations as rot
from stylesync.config import START_RAMPS, ClockConfig, OperatorConfig
from stylesync.sources.base import RecordedSource
from stylesync.sources.deepmimic_clip import CLIP_CHARACTER_LEG_LENGTH_M, DeepMimicClip
from stylesync.sources.frame import OperatorFrame
from stylesync.sources.human_model import HumanModel
from stylesync.sources.sensor_model import SensorModel
from stylesync.sources.turning_path import TurningPath

# The rate ramp starts a looping clip only where it has a pose with both ankles within this of their lowest (a stance
# on both feet; heel and toe roll within it): a run's feet are never both down, and it is blended in [m]
RATE_RAMP_MAX_FOOT_UP_M = 0.05
STAND_CLIP = "stand"  # an operator standing still, for balance checks
_RAMP_GRID_HZ = 240.0  # grid of the ramped pelvis path's integral


class ClipPerformer:
    """Noise-free operator frames of a human skeleton playing a clip."""

    def __init__(self, clip: DeepMimicClip | None, human: HumanModel, lead_in_s: float = 0.0,
                 blend_s: float = 0.5, start_ramp_s: float = 0.0, speed: float = 1.0, ramp: str = "blend"):
        if ramp not in START_RAMPS:
            raise ValueError(f"start ramp {ramp!r}: expected one of {', '.join(START_RAMPS)}")
        self.clip = clip
        self.speed = speed  # the clip's time runs this many times faster than the run's after the lead-in [-]
        self.human = human
        self.lead_in_s = lead_in_s
        self.leg_ratio = (human.hip_height_m) / CLIP_CHARACTER_LEG_LENGTH_M
        self.start_ramp_s = start_ramp_s if clip is not None and clip.loop else 0.0
        self.blend_s = 0.0 if self.start_ramp_s > 0 else min(blend_s, lead_in_s)
        self._stand_root, self._stand_quats = self._standing()
        # The clip's time the rate ramp starts from: the phase where his feet are nearest the ground [s]; a clip with
        # no pose on both feet (a run) is blended in from a stand instead
        self.start_phase_s, self.rate_ramp = 0.0, False
        if self.start_ramp_s > 0 and ramp == "rate":
            phase_s, higher_m = self._lowest_feet_phase_s()
            if higher_m <= RATE_RAMP_MAX_FOOT_UP_M:
                self.start_phase_s, self.rate_ramp = phase_s, True
        if self.start_ramp_s > 0 and not self.rate_ramp:
            # ∫_0^s (p_clip(s') - p_clip(0)) ds' on a fine grid, for the blend's pelvis path
            self._ramp_t = np.linspace(0.0, self.start_ramp_s, int(self.start_ramp_s * _RAMP_GRID_HZ) + 2)
            self._clip_root_0 = self._clip_root(0.0)
            p = np.array([self._clip_root(t) for t in self._ramp_t]) - self._clip_root_0
            steps = 0.5 * (p[1:] + p[:-1]) * np.diff(self._ramp_t)[:, None]
            self._ramp_integral = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])

    def _clip_root(self, t_s: float) -> np.ndarray:
        assert self.clip is not None
        return self.clip.pose_at(t_s).root_pos_world * self.leg_ratio

    def _clip_frame(self, t_s: float, u_s: float) -> OperatorFrame:
        """His frame at the run's time ``t_s`` [s] in the clip's own pose at its time ``u_s`` [s], the pelvis's path
        scaled to his legs."""
        assert self.clip is not None
        pose = self.clip.pose_at(u_s)
        return self.human.frame_from_pose(t_s, pose.root_pos_world * self.leg_ratio, pose.local_quats)

    def _lowest_feet_phase_s(self) -> tuple[float, float]:
        """The clip time [s] in its first cycle, on its own frames, where the higher of his two ankles is lowest
        above that ankle's lowest in the cycle (a walk's double stance; the first such frame), and that height [m]."""
        assert self.clip is not None
        times = [t for t in self.clip.times if t < self.clip.duration_s] or [0.0]
        heights = []
        for t in times:
            f = self._clip_frame(0.0, t)
            heights.append((float(f.pos("ANKLE_LEFT")[2]), float(f.pos("ANKLE_RIGHT")[2])))
        z = np.array(heights)
        above = (z - z.min(axis=0)).max(axis=1)
        k = int(np.argmin(above))
        return float(times[k]), float(above[k])

    def clip_time_s(self, t_s: float) -> float:
        """The clip's time [s] at the run's time ``t_s`` [s] with the rate ramp: his start phase through the
        lead-in, then u_0 + speed (τ² / (2 T) for τ < T, τ - T / 2 after), τ the time since the lead-in, T the ramp."""
        tau = max(t_s - self.lead_in_s, 0.0)
        ramp = self.start_ramp_s
        warped = tau * tau / (2.0 * ramp) if tau < ramp else tau - 0.5 * ramp
        return self.start_phase_s + self.speed * warped

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
        if self.clip is not None and self.rate_ramp:
            return self._clip_frame(t_s, self.clip_time_s(t_s))
        stand_root, stand_quats = self._stand_root, self._stand_quats
        if self.clip is None or t_s < self.lead_in_s - self.blend_s:
            return self.human.frame_from_pose(t_s, stand_root, stand_quats)
        u_s = self.speed * (t_s - self.lead_in_s)  # the clip's time [s]
        if self.start_ramp_s > 0:
            return self.human.frame_from_pose(t_s, *self._ramped(u_s))
        if t_s >= self.lead_in_s:
            return self._clip_frame(t_s, u_s)
        # blend from standing into the clip's first pose
        pose = self.clip.pose_at(0.0)
        a = 1.0 - (self.lead_in_s - t_s) / self.blend_s
        root = (1 - a) * stand_root + a * (pose.root_pos_world * self.leg_ratio)
        quats = {k: rot.slerp(stand_quats.get(k, rot.IDENTITY_WXYZ), q, a) for k, q in pose.local_quats.items()}
        return self.human.frame_from_pose(t_s, root, quats)


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
                              speed=operator.playback_speed, ramp=operator.start_ramp)
    pose_at: Callable[[float], OperatorFrame] = performer.frame_at
    if operator.turn_rate_rad_s != 0.0:
        pose_at = TurningPath(pose_at, operator.turn_rate_rad_s, operator.standing_lead_in_s, duration_s)
    return sensed(pose_at, operator, clocks, duration_s, seed, f"builtin:{operator.clip}"), performer


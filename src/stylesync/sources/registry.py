"""Opening an operator source from a spec string (``stylesync run --source SPEC``).

Specs: ``bvh:PATH``, ``k4a-json:PATH``, ``deepmimic:NAME|PATH`` (pybullet_data clip name, or a clip file),
``builtin:NAME`` (same as the demo), ``vmc://HOST:PORT``, ``webcam:INDEX``, ``video:PATH``, ``k4a:DEVICE`` (live Azure
Kinect). Recorded sources pass through the sensor model: ``kinect`` resamples to the mocap rate (16 Hz) with noise,
jitter and dropouts from the seed; ``none`` passes the recorded frames at their own rate (the processing stage then
interpolates from that rate). A recorded file starts in motion (the character in the first frame's state) and ends
with the operator holding the last frame for ``rest_after_clip_s``; with ``start_in_motion`` off, and for clips
(deepmimic, builtin), the operator first holds the first pose for ``standing_lead_in_s``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stylesync.config import ClockConfig, OperatorConfig
from stylesync.errors import SourceError
from stylesync.sources.base import OperatorSource, RecordedSource
from stylesync.sources.frame import OperatorFrame
from stylesync.sources.held_pose import put_feet_down
from stylesync.sources.sensor_model import SensorModel

SENSORS = ("kinect", "none")
FEET_DOWN_S = 0.5  # a held last pose's raised foot is lowered onto the ground over this time [s]
KINECT_DROPOUT_PROBABILITY = 0.002  # per joint and frame: occasional lost joints, as a depth sensor has


@dataclass
class OpenedSource:
    source: OperatorSource
    mocap_hz: float  # rate the processing stage interpolates from [Hz]
    duration_s: float | None  # length of a recording (with its lead-in) [s]; None for a live stream
    label: str
    performer: object | None = None  # noise-free recording, ``frame_at(t)``
    # what the frames passed through: a recorded source's sensor model ("kinect", "none"), or "live" (the device's
    # or sender's own frames, no sensor model)
    sensor: str = "live"
    extras: dict[str, object] = field(default_factory=dict)  # what the source reports (metrics.json "source_info")


class _LeadIn:
    """Holds a performer's first pose for ``lead_in_s`` seconds, then plays it, then holds its last pose for
    ``rest_s`` seconds."""

    def __init__(self, performer, lead_in_s: float, rest_s: float = 0.0):
        self.performer, self.lead_in_s = performer, lead_in_s
        self.duration_s = performer.duration_s + lead_in_s + rest_s

    def frame_at(self, t_s: float) -> OperatorFrame:
        clip_t = t_s - self.lead_in_s
        f = self.performer.frame_at(max(0.0, clip_t))
        f.timestamp_s = t_s
        if clip_t > self.performer.duration_s:
            x = min((clip_t - self.performer.duration_s) / FEET_DOWN_S, 1.0)
            put_feet_down(f, 0.5 - 0.5 * float(np.cos(np.pi * x)))  # from 0 to 1 with zero slope at both ends
        return f


def _recorded(performer, label: str, sensor: str, clocks: ClockConfig, op: OperatorConfig, seed: int,
              duration_s: float | None) -> OpenedSource:
    if op.start_in_motion:
        lead = _LeadIn(performer, 0.0, op.rest_after_clip_s)
    else:
        lead = _LeadIn(performer, op.standing_lead_in_s)
    # A recording has nothing to give past its end and the rest after it: a longer duration asked for is cut there
    # (frames are made for the whole run up front).
    total = lead.duration_s if duration_s is None else duration_s
    if op.start_in_motion:
        total = min(total, lead.duration_s)
    if sensor == "kinect":
        model = SensorModel.kinect(op, clocks, seed, KINECT_DROPOUT_PROBABILITY)
        frames, rate = model.sample(lead.frame_at, total), clocks.mocap_hz
    elif sensor == "none":
        rate = getattr(performer, "rate_hz", 0.0) or clocks.mocap_hz
        frames = [lead.frame_at(k / rate) for k in range(int(total * rate) + 1)]
    else:
        raise SourceError(f"unknown sensor model '{sensor}'; expected one of {', '.join(SENSORS)}")
    if op.start_in_motion:
        # The run starts when the second frame arrives: the processing stage (Eq. 7) then moves from the first
        # frame towards it, and the character starts in the first frame's state moving at the clip's velocity
        # (session.py). Started at the first frame, the reference would hold still for a frame period.
        for f in frames:
            f.timestamp_s -= 1.0 / rate
    return OpenedSource(RecordedSource(frames, name=label, starts_in_motion=op.start_in_motion), rate,
                        lead.duration_s, label, lead, sensor)


def open_source(spec: str, clocks: ClockConfig | None = None, operator: OperatorConfig | None = None,
                sensor: str = "kinect", seed: int = 0, duration_s: float | None = None,
                joint_map: str | None = None, bvh_scale_m: float | None = None,
                bvh_up_axis: str | None = None) -> OpenedSource:
    clocks = clocks or ClockConfig()
    op = operator or OperatorConfig()
    kind, _, arg = spec.partition(":")
    if kind == "bvh":
        from stylesync.sources.bvh import BvhRecording, load_joint_map

        jm = load_joint_map(joint_map) if joint_map else None
        rec = BvhRecording(arg, joint_map=jm, scale_m=bvh_scale_m, up_axis=bvh_up_axis)
        return _recorded(rec.performer, spec, sensor, clocks, op, seed, duration_s)
    if kind == "k4a-json":
        from stylesync.sources.k4abt_json import K4abtRecording

        k4a = K4abtRecording(arg)
        opened = _recorded(k4a.performer, spec, sensor, clocks, op, seed, duration_s)
        opened.source.rejected_frames += k4a.rejected_frames
        return opened
    if kind in ("deepmimic", "builtin"):
        from stylesync.sources.builtin_operator import ClipPerformer
        from stylesync.sources.deepmimic_clip import DeepMimicClip
        from stylesync.sources.human_model import HumanModel

        is_path = arg.endswith(".txt") or "/" in arg
        clip = DeepMimicClip.load(arg) if is_path else DeepMimicClip.builtin(arg)
        human = HumanModel(op.height_m, op.mass_kg)
        performer = ClipPerformer(clip, human, op.standing_lead_in_s, start_ramp_s=op.start_ramp_s, ramp=op.start_ramp)
        total = (duration_s if duration_s is not None else
                 (clip.duration_s if not clip.loop else 12.0) + op.standing_lead_in_s)
        if sensor == "kinect":
            model = SensorModel.kinect(op, clocks, seed, KINECT_DROPOUT_PROBABILITY)
        elif sensor == "none":  # the clip itself, sampled at the mocap rate
            model = SensorModel(rate_hz=clocks.mocap_hz, position_noise_m=0.0, orientation_noise_rad=0.0,
                                timestamp_jitter_s=0.0, seed=seed)
        else:
            raise SourceError(f"unknown sensor model '{sensor}'; expected one of {', '.join(SENSORS)}")
        return OpenedSource(RecordedSource(model.sample(performer.frame_at, total), name=spec), clocks.mocap_hz,
                            total, spec, performer, sensor)
    if spec.startswith("vmc://"):
        from stylesync.sources.vmc import DEFAULT_PORT, VmcSource

        host, _, port = spec.removeprefix("vmc://").partition(":")
        try:
            port_n = int(port) if port else DEFAULT_PORT
        except ValueError:
            raise SourceError(f"VMC port must be a number: '{spec}'") from None
        if not 0 <= port_n <= 65535:
            raise SourceError(f"VMC port must be 0-65535: '{spec}'")
        return OpenedSource(VmcSource(host or "127.0.0.1", port_n), 60.0, None, spec)
    if kind == "video":
        from stylesync.sources.webcam import VideoRecording

        video = VideoRecording(arg)
        # The pose model's landmarks are the sensor: no sensor model on top.
        opened = _recorded(video.performer, spec, "none", clocks, op, seed, duration_s)
        opened.extras["camera_tilt_deg"] = round(video.camera_tilt_deg, 2)
        opened.extras["video_frames"] = video.frames
        opened.extras["video_frames_without_person"] = video.frames_without_person
        opened.extras["video_frame_rate_hz"] = video.frame_rate_hz
        return opened
    if kind == "webcam":
        from stylesync.sources.webcam import MediaPipeSource

        return OpenedSource(MediaPipeSource(arg, is_file=False), 30.0, None, spec)
    if kind == "k4a":
        from stylesync.sources.azure_kinect import AzureKinectSource

        return OpenedSource(AzureKinectSource(int(arg or 0)), 30.0, None, spec)
    if kind and Path(spec).suffix.lower() == ".bvh":
        raise SourceError(f"unknown source '{spec}'; did you mean bvh:{spec}?")
    raise SourceError(f"unknown source '{spec}'; expected bvh:PATH, k4a-json:PATH, deepmimic:NAME|PATH, "
                      f"builtin:NAME, vmc://HOST:PORT, webcam:INDEX, video:PATH or k4a:DEVICE")

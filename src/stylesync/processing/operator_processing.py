"""The data-processing stage (Sec. 4.3, Fig. 4): mocap frames in at 16 Hz, smoothed samples out at 133 Hz.

Per mocap frame: joints the sensor lost (confidence 0) keep their last valid value (counted), the operator COM
is computed from the joints (Eq. 6) and floor-filtered. Per control tick: everything is interpolated (Eq. 7) and
joint values pass the 1€ filter (Eq. 8). Orientations are filtered component-wise after sign alignment and
renormalised; positions (needed by the stance FSM and the pose optimisation) pass the same 1€ filter.

The 1€-filtered ankles are also floor-filtered, as the COM, into ``support_ankle_world``: the COM target of the
balance control is the operator's COM placed relative to his feet (Eq. 10), and the feet's 1€-filtered jitter, a
millimetre or two at a few Hz, would otherwise reach the balance control through them (a standing character then
rocked from foot to foot by ±100 N at 4 Hz). The 1€-filtered ankles still drive the stance FSM and the swing foot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ClockConfig, FilterConfig
from stylesync.processing.body_parameters import com_from_joints
from stylesync.processing.floor_filter import FloorFilter
from stylesync.processing.interpolation import LinearRamp, SlerpRamp
from stylesync.processing.joint_map import TRACKED_ORIENTATIONS, TRACKED_POSITIONS, tracked_arrays
from stylesync.processing.one_euro import OneEuroFilter
from stylesync.sources.frame import OperatorFrame

_ANKLE = {"left": "ANKLE_LEFT", "right": "ANKLE_RIGHT"}


@dataclass
class OperatorSample:
    """The smoothed operator at one control tick (world frame, operator scale)."""

    time_s: float
    quat: dict[str, np.ndarray]  # canonical world segment orientation per tracked joint
    pos: dict[str, np.ndarray]  # world position per tracked joint [m]
    com_world: np.ndarray  # (3,) floor-filtered, interpolated operator COM [m]
    support_ankle_world: dict[str, np.ndarray]  # "left"/"right": the 1€-filtered ankle, then floor-filtered [m]
    mocap_time_s: float  # timestamp of the newest mocap frame used


class OperatorProcessing:
    def __init__(self, clocks: ClockConfig, filters: FilterConfig):
        period = 1.0 / clocks.control_hz
        self._qramp = SlerpRamp(clocks.mocap_hz, clocks.control_hz)
        self._pramp = LinearRamp(clocks.mocap_hz, clocks.control_hz)
        # One element-wise 1€ filter over the orientations' components, then the positions' (one call per tick).
        self._filter = OneEuroFilter(period, filters.one_euro_min_cutoff_hz, filters.one_euro_beta,
                                     filters.one_euro_derivative_cutoff_hz)
        self._floor = FloorFilter(filters.floor_threshold_m)
        self._ankle_floor = {side: FloorFilter(filters.floor_threshold_m) for side in _ANKLE}
        self._last_q: np.ndarray | None = None
        self._last_p: np.ndarray | None = None
        self._q_prev_out: np.ndarray | None = None
        self.dropped_joint_values = 0
        self.mocap_time_s = -np.inf

    @property
    def ready(self) -> bool:
        return self._last_q is not None

    def push(self, frame: OperatorFrame) -> None:
        q, p, cq, cp = tracked_arrays(frame)
        if self._last_q is None or self._last_p is None:
            if np.any(cq <= 0) or np.any(cp <= 0):
                self.dropped_joint_values += int(np.sum(cq <= 0) + np.sum(cp <= 0))
                return  # cannot start from a frame with lost joints
            self._last_q, self._last_p = q.copy(), p.copy()
        lost_q, lost_p = cq <= 0, cp <= 0
        self.dropped_joint_values += int(lost_q.sum() + lost_p.sum())
        q = np.where(lost_q[:, None], self._last_q, q)
        p = np.where(lost_p[:, None], self._last_p, p)
        self._last_q, self._last_p = q, p
        com = self._floor(com_from_joints(dict(zip(TRACKED_POSITIONS, p, strict=True))))  # Eq. 6, floor filter
        self._qramp.push(q)
        self._pramp.push(np.vstack([p, com[None, :]]))
        self.mocap_time_s = frame.timestamp_s

    def prime_rates(self, f0: OperatorFrame, f1: OperatorFrame) -> None:
        """Start the 1€ filter (Eq. 8) with the rates from frame ``f0`` to the later ``f1``: an operator who is
        already moving at the first frame (a recording that starts mid-motion) is filtered with the lag of his
        speed from the start, not with the larger one of a filter that believes him at rest."""
        dt = f1.timestamp_s - f0.timestamp_s
        if not dt > 0:
            return
        q0, p0, _, _ = tracked_arrays(f0)
        q1, p1, _, _ = tracked_arrays(f1)
        q1 = rot.batch_align_sign(q1, q0)
        self._filter.prime(np.concatenate([(q1 - q0).reshape(-1), (p1 - p0).reshape(-1)]) / dt)

    def step(self, time_s: float) -> OperatorSample:
        q = self._qramp.step()  # Eq. 7
        if self._q_prev_out is not None:
            q = rot.batch_align_sign(q, self._q_prev_out)
        pc = self._pramp.step()
        filtered = self._filter(np.concatenate([q.reshape(-1), pc[:-1].reshape(-1)]))  # Eq. 8
        q = filtered[:q.size].reshape(q.shape)
        q = q / np.sqrt(np.einsum("ij,ij->i", q, q))[:, None]
        self._q_prev_out = q
        p, com = filtered[q.size:].reshape(-1, 3), pc[-1]
        pos = dict(zip(TRACKED_POSITIONS, p, strict=True))
        return OperatorSample(
            time_s=time_s,
            quat=dict(zip(TRACKED_ORIENTATIONS, q, strict=True)),
            pos=pos,
            com_world=com,
            support_ankle_world={side: self._ankle_floor[side](pos[name]) for side, name in _ANKLE.items()},
            mocap_time_s=self.mocap_time_s,
        )

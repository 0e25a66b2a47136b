"""Run metrics written to metrics.json (definitions in docs/metrics.md)."""

from __future__ import annotations

import numpy as np

from stylesync.metrics import imitation as im
from stylesync.model.state import CONTACT_FORCE_N
from stylesync.motion.stance_fsm import Stance
from stylesync.session import STANCE_CODE, SessionResult

_DS = STANCE_CODE[Stance.DS]


def touchdowns(states: np.ndarray) -> np.ndarray:
    """Indices where the state enters DS from a single stance (one step each)."""
    s = np.asarray(states)
    return np.where((s[1:] == _DS) & (s[:-1] != _DS))[0] + 1


def transition_delays(t: np.ndarray, op: np.ndarray, ch: np.ndarray, window_s: float = 1.0) -> list[float]:
    """For each operator state change, the time until the character first enters the same state [s].

    A character already in that state (early contact) counts as 0; one that never gets there within
    ``window_s`` counts as ``window_s``. A change the character has not followed by the end of the log, less than
    ``window_s`` before it, is left out: its delay is not known (a run that ends 40 ms after the operator's last
    lift-off would otherwise count a delay of ``window_s``).
    """
    delays = []
    for i in np.where(op[1:] != op[:-1])[0] + 1:
        target = op[i]
        if ch[i] == target:
            delays.append(0.0)
            continue
        later = np.where((ch[i:] == target) & (t[i:] <= t[i] + window_s))[0]
        if len(later):
            delays.append(float(t[i + later[0]] - t[i]))
        elif t[-1] >= t[i] + window_s:
            delays.append(window_s)
    return delays


def summarize(result: SessionResult) -> dict:
    lg = result.log
    t = lg.array("t")
    op, ch = lg.array("op_state").astype(int), lg.array("char_state").astype(int)
    delays = transition_delays(t, op, ch)
    com = np.stack([lg.array("com_x"), lg.array("com_y")], axis=1)
    com_d = np.stack([lg.array("com_d_x"), lg.array("com_d_y")], axis=1)
    com_err = np.linalg.norm(com - com_d, axis=1) if len(t) else np.zeros(1)
    tick = np.array(result.stage_ms["processing"]) + np.array(result.stage_ms["motion"]) + np.array(
        result.stage_ms["control_update"]) if result.stage_ms["processing"] else np.zeros(1)
    return {
        "fell": result.fell,
        "fall_time_s": result.fall_time_s,
        "fall_reason": result.fall_reason,
        "sim_duration_s": round(result.sim_duration_s, 4),
        "operator_steps": int(len(touchdowns(op))),
        "character_steps": int(len(touchdowns(ch))),
        "realtime_factor": round(result.sim_duration_s / max(result.wall_duration_s, 1e-9), 3),
        "operator_prefetched": result.operator_prefetched,  # operator side in a second process (prefetch.py)
        "control_tick_ms": {"p50": float(np.percentile(tick, 50)), "p99": float(np.percentile(tick, 99))},
        "state_transition_delay_s": {
            "mean": float(np.mean(delays)) if delays else 0.0,
            "p95": float(np.percentile(delays, 95)) if delays else 0.0,
            "max": float(np.max(delays)) if delays else 0.0,
            "count": len(delays),
        },
        "com_error_m": {"mean": float(com_err.mean()), "max": float(com_err.max())},
        "joint_error_deg": {"mean": float(lg.array("joint_err_deg").mean()) if len(t) else 0.0},
        "rejected_frames": result.rejected_frames,
        "rejections": dict(result.rejections),  # a live source's rejected packets or frames by reason
        # a run that went on after its fall (--continue-after-fall, a viewer) ended by its duration or its reason
        "ended_by": ("fall" if result.fell and abs(result.sim_duration_s - (result.fall_time_s or 0.0)) < 1e-6
                     else (result.end_reason or "duration")),
        "dropped_joint_values": result.dropped_joint_values,
        "bound_violations": result.bound_counts,
        "input_latency_ms": _latency(result.input_latency_ms),
    } | imitation_metrics(result)


def imitation_metrics(result: SessionResult) -> dict:
    """MPJPE, UHC/PHC fall, foot skating, jitter and synchronisation lag (imitation.py)."""
    lg = result.log
    t = lg.array("t")
    if len(t) < 3:
        return {}
    dt = float(np.median(np.diff(t)))
    ch = lg.array("ch_joints")
    ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
    uhc = im.uhc_fall_index(ch, ref)
    imitating = im.ticks_before_termination(uhc, len(t))  # (im.mpjpe_before_termination_mm, its index found once)
    feet = [im.JOINT_PAIRS.index(("left_ankle", "ANKLE_LEFT")), im.JOINT_PAIRS.index(("right_ankle", "ANKLE_RIGHT"))]
    progress, sideways = im.path_progress(ch[:, 0], ref[:, 0])
    rel_ch, rel_ref = ch - ch[:, :1], ref - ref[:, :1]
    foot_down = np.stack([lg.array("contact_l"), lg.array("contact_r")], axis=1) > CONTACT_FORCE_N
    return {
        "mpjpe_global_mm": round(im.mpjpe_mm(ch, ref), 1),
        "mpjpe_root_mm": round(im.mpjpe_mm(ch, ref, root_relative=True), 1),
        "mpjpe_global_before_uhc_mm": round(im.mpjpe_mm(ch[:imitating], ref[:imitating]), 1),
        "mpjpe_root_before_uhc_mm": round(im.mpjpe_mm(ch[:imitating], ref[:imitating], root_relative=True), 1),
        "uhc_fall_time_s": None if uhc is None else float(t[uhc]),
        "uhc_cause": None if uhc is None else im.termination_split(t, ch, ref, uhc)["cause"],
        "path_progress": None if progress is None else round(progress, 3),
        "path_sideways_m": None if sideways is None else round(sideways, 3),
        "foot_skate_mm": round(im.foot_skate_mm(ch[:, feet], foot_down), 3),
        "jitter_mps2": round(im.jitter_mps2(ch, dt), 3),
        "sync_lag_s": round(im.sync_lag_s(rel_ref.reshape(len(t), -1), rel_ch.reshape(len(t), -1), dt), 4),
        "step_width_m": {who: None if w is None else round(w, 4) for who, w in (
            ("character", im.median_step_width_m(ch, touchdowns(lg.array("char_state")))),
            ("operator", im.median_step_width_m(ref, touchdowns(lg.array("op_state")))))},
    }


def _latency(ms: list[float]) -> dict | None:
    """Live frames: time from a frame's arrival to the first control tick that uses it [ms]."""
    if not ms:
        return None
    a = np.asarray(ms)
    return {"p50": float(np.percentile(a, 50)), "p95": float(np.percentile(a, 95)), "max": float(a.max()),
            "count": len(a)}

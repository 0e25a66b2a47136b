"""Field-standard motion-imitation metrics (definitions in docs/metrics.md).

Inputs are per-control-tick arrays: positions (T, J, 3) in metres in the world frame (z up), times in seconds.
The operator's joints are first scaled to the character (:func:`scale_operator_to_character`), as in physics-based
imitation benchmarks (UHC, PHC), so that errors measure imitation rather than the difference in body size.
"""

from __future__ import annotations

import numpy as np

from stylesync.model.character import CHARACTER_LINKS, JOINT_PAIRS, OPERATOR_JOINTS

__all__ = ["CHARACTER_LINKS", "JOINT_PAIRS", "OPERATOR_JOINTS"]

UHC_FALL_DISTANCE_M = 0.5  # termination when the mean joint distance exceeds this (UHC/PHC) [m]
_LEFT_HIP, _RIGHT_HIP = OPERATOR_JOINTS.index("HIP_LEFT"), OPERATOR_JOINTS.index("HIP_RIGHT")


def scale_operator_to_character(op_pos: np.ndarray, scale: np.ndarray | float, char_root0: np.ndarray) -> np.ndarray:
    """Operator joints (T, J, 3) scaled by the leg-length ratio (Eq. 9) about the operator's first pelvis ground
    point (joint 0) and moved onto the character's first pelvis ground point ``char_root0``."""
    op_pos = np.asarray(op_pos, dtype=float)
    s = np.broadcast_to(np.asarray(scale, dtype=float), (op_pos.shape[0],))[:, None, None]
    base = np.array([op_pos[0, 0, 0], op_pos[0, 0, 1], 0.0])
    anchor = np.array([char_root0[0], char_root0[1], 0.0])
    return anchor + s * (op_pos - base)


def mpjpe_mm(char_pos: np.ndarray, ref_pos: np.ndarray, root_relative: bool = False) -> float:
    """Mean per-joint position error [mm]; root-relative subtracts joint 0 (the pelvis) from both first."""
    a, b = np.asarray(char_pos, dtype=float), np.asarray(ref_pos, dtype=float)
    if root_relative:
        a = a - a[:, :1]
        b = b - b[:, :1]
    return float(np.linalg.norm(a - b, axis=-1).mean() * 1e3)


def facing_rad(pos: np.ndarray) -> np.ndarray:
    """(T,) the facing [rad] of each tick's (T, J, 3) joints in JOINT_PAIRS order: the hip line from right to left,
    turned a quarter to the right (the heading the pelvis faces), about world z."""
    d = np.asarray(pos, dtype=float)
    d = d[:, _LEFT_HIP] - d[:, _RIGHT_HIP]
    return np.arctan2(d[:, 1], d[:, 0]) - 0.5 * np.pi


def facing_error_deg(char_pos: np.ndarray, ref_pos: np.ndarray) -> np.ndarray:
    """(T,) the character's facing against the reference's [deg], within [-180, 180) (:func:`facing_rad`)."""
    return (np.degrees(facing_rad(char_pos) - facing_rad(ref_pos)) + 180.0) % 360.0 - 180.0


def uhc_fall_index(char_pos: np.ndarray, ref_pos: np.ndarray, limit_m: float = UHC_FALL_DISTANCE_M) -> int | None:
    """First tick whose mean joint distance to the reference exceeds ``limit_m`` (UHC/PHC termination), or None."""
    d = np.linalg.norm(np.asarray(char_pos) - np.asarray(ref_pos), axis=-1).mean(axis=1)
    over = np.where(d > limit_m)[0]
    return int(over[0]) if len(over) else None


def mpjpe_before_termination_mm(char_pos: np.ndarray, ref_pos: np.ndarray, root_relative: bool = False,
                                limit_m: float = UHC_FALL_DISTANCE_M) -> float:
    """:func:`mpjpe_mm` over the ticks before the UHC/PHC termination (:func:`uhc_fall_index`; every tick without
    one, at least the first) [mm]: the field's runs end there. Two controllers are then compared on the ticks each
    imitates; a character that goes on after its termination is not charged for how far it drifts since (how long
    each imitates is the termination's time)."""
    end = ticks_before_termination(uhc_fall_index(char_pos, ref_pos, limit_m), len(char_pos))
    return mpjpe_mm(np.asarray(char_pos)[:end], np.asarray(ref_pos)[:end], root_relative)


def ticks_before_termination(termination_tick: int | None, n_ticks: int) -> int:
    """How many of a run's ``n_ticks`` come before its UHC/PHC termination at ``termination_tick``
    (:func:`uhc_fall_index`; None: every tick), at least the first."""
    return n_ticks if termination_tick is None else max(termination_tick, 1)


TERMINATION_WAY_WINDOW_S = 0.5  # his way at a termination: his pelvis's displacement over this time [s]
TERMINATION_IN_PLACE_M = 0.1  # ... less than this: he goes nowhere [m]
TERMINATION_CAUSES = ("behind", "ahead", "aside", "height", "pose", "in place")  # termination_split's causes


def termination_split(t_s: np.ndarray, char_pos: np.ndarray, ref_pos: np.ndarray, tick: int,
                      speed_window_s: float = 1.0) -> dict:
    """The mean joint distance of ``char_pos`` from ``ref_pos`` ((T, J, 3), world, metres, joint 0 the pelvis; times
    ``t_s`` (T,) [s]) at ``tick`` (a UHC/PHC termination, :func:`uhc_fall_index`), split into where the character's
    pelvis is from his and how its pose differs: ``along`` his way over the ground (his pelvis's displacement over the
    last TERMINATION_WAY_WINDOW_S; < 0 behind him), ``across`` it (a distance), ``height`` (its less his) [m] and
    ``pose``, the mean distance with both pelvises put together [m]; with ``distance``, both pelvises' straight-line
    speeds over ``speed_window_s`` before (``his_mps``, ``its_mps``) and ``cause``, the largest of the four parts:
    ``behind`` or ``ahead`` along his way, ``aside``, ``height`` or ``pose``, and ``in place`` for a pelvis offset
    where he went less than TERMINATION_IN_PLACE_M (his way is then no direction). The parts do not add up to the
    distance (a mean of lengths): the largest says what it mostly is."""
    t = np.asarray(t_s, dtype=float)
    ch, ref = np.asarray(char_pos, dtype=float), np.asarray(ref_pos, dtype=float)
    k0 = int(np.searchsorted(t, t[tick] - TERMINATION_WAY_WINDOW_S))
    way = ref[tick, 0, :2] - ref[k0, 0, :2]
    moved = float(np.hypot(way[0], way[1]))
    e = way / moved if moved > 1e-9 else np.array([1.0, 0.0])
    off = ch[tick, 0] - ref[tick, 0]
    along = float(off[:2] @ e)
    across = abs(float(off[1] * e[0] - off[0] * e[1]))
    pose = float(np.linalg.norm((ch[tick] - ch[tick, :1]) - (ref[tick] - ref[tick, :1]), axis=1).mean())
    parts = {"along": abs(along), "across": across, "height": abs(float(off[2])), "pose": pose}
    cause = max(parts, key=lambda p: parts[p])
    if cause in ("along", "across") and moved < TERMINATION_IN_PLACE_M:
        cause = "in place"  # his way is no direction
    elif cause == "across":
        cause = "aside"
    elif cause == "along":
        cause = "behind" if along < 0.0 else "ahead"
    ks = int(np.searchsorted(t, t[tick] - speed_window_s))
    span = max(float(t[tick] - t[ks]), 1e-9)
    return {"distance": float(np.linalg.norm(ch[tick] - ref[tick], axis=1).mean()), "along": along,
            "across": across, "height": float(off[2]), "pose": pose, "cause": cause,
            "his_mps": float(np.hypot(*(ref[tick, 0, :2] - ref[ks, 0, :2]))) / span,
            "its_mps": float(np.hypot(*(ch[tick, 0, :2] - ch[ks, 0, :2]))) / span}


PATH_MIN_DISTANCE_M = 0.5  # an operator who moves less than this over the ground has no path to follow [m]


def path_progress(char_root_world: np.ndarray, ref_root_world: np.ndarray,
                  min_distance_m: float = PATH_MIN_DISTANCE_M) -> tuple[float | None, float | None]:
    """How far the character went along its operator's path: its root's horizontal displacement from the first to
    the last tick, projected on the (scaled) operator's, over the length of his (1: as far as he went, 0: in place,
    negative: the other way), and its distance sideways of his line [m]. ``char_root_world`` and ``ref_root_world``
    (T, 3) in metres; (None, None) when he moved less than ``min_distance_m``."""
    c = np.asarray(char_root_world, dtype=float)
    r = np.asarray(ref_root_world, dtype=float)
    dc, dr = c[-1, :2] - c[0, :2], r[-1, :2] - r[0, :2]
    length = float(np.hypot(dr[0], dr[1]))
    if length < min_distance_m:
        return None, None
    return float(dc @ dr) / length**2, abs(float(dc[0] * dr[1] - dc[1] * dr[0])) / length


_LEFT_ANKLE, _RIGHT_ANKLE = OPERATOR_JOINTS.index("ANKLE_LEFT"), OPERATOR_JOINTS.index("ANKLE_RIGHT")


def step_widths_m(pos: np.ndarray, touchdown_ticks: np.ndarray) -> np.ndarray:
    """The step width at each of ``touchdown_ticks`` [m]: how far the left ankle lies left of the right one across
    the pelvis, along the hip line from right to left (:func:`facing_rad`'s), horizontally, in each tick's
    (T, J, 3) joints in JOINT_PAIRS order. Negative: the feet crossed. A walk's feet land 0.1-0.2 m apart
    (scaled); feet in line give 0."""
    d = np.asarray(pos, dtype=float)[np.asarray(touchdown_ticks, dtype=int)]
    hips = d[:, _LEFT_HIP, :2] - d[:, _RIGHT_HIP, :2]
    across = hips / np.maximum(np.linalg.norm(hips, axis=1, keepdims=True), 1e-9)
    return np.einsum("ij,ij->i", d[:, _LEFT_ANKLE, :2] - d[:, _RIGHT_ANKLE, :2], across)


def median_step_width_m(pos: np.ndarray, touchdown_ticks: np.ndarray) -> float | None:
    """The median of :func:`step_widths_m` over ``touchdown_ticks`` [m]; None without a touchdown."""
    return float(np.median(step_widths_m(pos, touchdown_ticks))) if len(touchdown_ticks) else None


def foot_skate_mm(foot_pos: np.ndarray, in_contact: np.ndarray) -> float:
    """Foot skating [mm]: mean horizontal displacement, per tick, of a foot that is in contact at both ends of the
    tick. ``foot_pos`` (T, F, 3), ``in_contact`` (T, F) booleans."""
    p = np.asarray(foot_pos, dtype=float)
    c = np.asarray(in_contact, dtype=bool)
    both = c[1:] & c[:-1]
    if not both.any():
        return 0.0
    step = np.linalg.norm(p[1:, :, :2] - p[:-1, :, :2], axis=-1)
    return float(step[both].mean() * 1e3)


def jitter_mps2(pos: np.ndarray, dt_s: float) -> float:
    """Jitter: mean joint acceleration magnitude by second differences [m/s^2]."""
    p = np.asarray(pos, dtype=float)
    if len(p) < 3:
        return 0.0
    acc = (p[2:] - 2 * p[1:-1] + p[:-2]) / dt_s**2
    return float(np.linalg.norm(acc, axis=-1).mean())


def sync_lag_s(operator: np.ndarray, character: np.ndarray, dt_s: float, max_lag_s: float = 1.0) -> float:
    """Synchronisation lag [s]: the shift of the character's trajectories that best aligns them with the
    operator's, by normalised cross-correlation summed over channels (positive: the character is late).

    ``operator`` and ``character`` are (T, K) channel arrays sampled every ``dt_s``.
    """
    a = np.asarray(operator, dtype=float).reshape(len(operator), -1)
    b = np.asarray(character, dtype=float).reshape(len(character), -1)
    a = a - a.mean(axis=0)
    b = b - b.mean(axis=0)
    n = len(a)
    max_k = min(int(round(max_lag_s / dt_s)), n // 2)
    best, best_k = -np.inf, 0
    for k in range(-max_k, max_k + 1):
        x, y = (a[: n - k], b[k:]) if k >= 0 else (a[-k:], b[: n + k])
        denom = np.sqrt((x * x).sum(axis=0) * (y * y).sum(axis=0))
        valid = denom > 1e-12
        if not valid.any():
            continue
        score = float(((x * y).sum(axis=0)[valid] / denom[valid]).mean())
        if score > best:
            best, best_k = score, k
    return best_k * dt_s

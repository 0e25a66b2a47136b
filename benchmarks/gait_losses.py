"""Where a walking character loses speed: its landings, and how near its leg actuators are to their limits (prints
figures; a tool for explaining why a walk falls behind its operator).

    python benchmarks/gait_losses.py walk:0 10_04:0 08_01:1 [--from 1.5] [--duration 12]

Each argument is a development-suite clip (`stylesync bench --suite dev`: a humanoid3d clip or a file of
../shared/mocap) and a sensor seed, run as the suite runs it (benchmarks/trace_run.py). Over the run from ``--from``
to the UHC termination (the field's end of an imitation run; the run's end without one), or with ``--whole`` to the
end of his clip (how the walk goes on past the termination), each of the character's landings (a single stance of
its ending) is put in one of two kinds: *with his*, the operator on both feet or on the other foot by then, and
*before his*, the operator still on the same foot (its step landed before his: a step of its own, mostly a swing taken
over at the reach limit). Per kind:

    landings       how many
    speed lost     the character's COM speed along his way over the 0.05 s before the landing, less the least over
                   the 0.25 s after it, summed over the kind's landings [m/s] (his way: his scaled COM from the
                   run's start to the window's end)
    double stance  the mean time the character then stands on both feet [s]

and over the window, for the legs' joints (hips, knees, ankles), the share of the control ticks on which any axis's
torque is 0.98 of its limit or more, and the 95th percentile of each tick's largest share of the limit. A line per
run, then the totals over all runs.
"""

from __future__ import annotations

import argparse
import logging
from dataclasses import dataclass, field

import numpy as np
from trace_run import run_suite_clip

from stylesync.control.controller import TORQUE_LIMIT
from stylesync.metrics import imitation
from stylesync.model.character import JOINT_NAMES
from stylesync.motion.stance_fsm import Stance
from stylesync.session import STANCE_CODE, Session

LEG_JOINTS = [k for k, name in enumerate(JOINT_NAMES) if name.endswith(("_hip", "_knee", "_ankle"))]
AT_LIMIT = 0.98  # a torque this share of its limit or more is at the limit [-]
BEFORE_S, AFTER_S = 0.05, 0.25  # the speed before a landing and the window after it [s]
DS = STANCE_CODE[Stance.DS]


@dataclass
class Kind:
    """The landings of one kind: their count, the speed lost summed [m/s] and the double stances' times [s]."""
    landings: int = 0
    lost_mps: float = 0.0
    stances_s: list[float] = field(default_factory=list)

    def add(self, other: Kind) -> None:
        self.landings += other.landings
        self.lost_mps += other.lost_mps
        self.stances_s += other.stances_s

    def text(self) -> str:
        ds = f"{np.mean(self.stances_s):.2f} s" if self.stances_s else "-"
        return f"{self.landings:3d} landings, speed lost {self.lost_mps:5.2f} m/s, double stance {ds}"


def _landings(t: np.ndarray, ch: np.ndarray, op: np.ndarray, along_mps: np.ndarray, k0: int, k1: int
              ) -> dict[str, Kind]:
    """The landings of the ticks [k0, k1) by kind ("with his", "before his")."""
    kinds = {"with his": Kind(), "before his": Kind()}
    dt = float(t[1] - t[0])
    before, after = max(int(round(BEFORE_S / dt)), 1), int(round(AFTER_S / dt))
    for k in range(max(k0, 1), k1):
        if ch[k - 1] == DS or ch[k] == ch[k - 1]:
            continue
        kind = kinds["before his" if op[k] == ch[k - 1] else "with his"]
        end = k
        while end < len(t) - 1 and ch[end] == ch[k]:
            end += 1
        kind.landings += 1
        kind.lost_mps += float(along_mps[max(k - before, 0):k].mean() - along_mps[k:min(k + after, len(t))].min())
        if ch[k] == DS:
            kind.stances_s.append(float(t[end] - t[k]))
    return kinds


def gait_losses(clip: str, seed: int, duration_s: float, from_s: float, whole: bool = False
                ) -> tuple[str, dict[str, Kind], np.ndarray]:
    """One run's line of figures, its landings by kind and the legs' largest torque share of each tick (n,); with
    ``whole``, to the end of his clip rather than to the UHC termination."""
    shares: list[tuple[float, float]] = []  # time [s], the legs' largest torque share of the limit [-]

    def on_tick_for(session: Session):
        def on_tick(state, ref) -> None:
            tau = np.abs(session.controller.torques(None).values[LEG_JOINTS]) / TORQUE_LIMIT[LEG_JOINTS]
            shares.append((state.time_s, float(tau.max())))
        return on_tick

    result, _, clip_end_s = run_suite_clip(clip, seed, duration_s, on_tick_for)
    log = result.log
    t = log.array("t")
    ch_joints = log.array("ch_joints")
    his = imitation.scale_operator_to_character(log.array("op_joints"), log.array("scale"), ch_joints[0, 0])
    uhc = imitation.uhc_fall_index(ch_joints, his)
    k1 = len(t) if uhc is None else int(uhc)
    if whole:
        k1 = int(np.searchsorted(t, clip_end_s))
    k0 = int(np.searchsorted(t, from_s))
    if k1 - k0 < 3:
        return f"{clip} seed {seed}: nothing to measure after {from_s:.1f} s", {}, np.zeros(0)
    his_com = np.c_[log.array("op_com_x"), log.array("op_com_y")] * log.array("scale")[:, None]
    way = his_com[k1 - 1] - his_com[0]
    u = way / max(float(np.linalg.norm(way)), 1e-9)
    com = np.c_[log.array("com_x"), log.array("com_y")]
    along_mps = np.gradient(com, t, axis=0) @ u
    kinds = _landings(t, log.array("char_state").astype(int), log.array("op_state").astype(int), along_mps, k0, k1)
    tick_t = np.array([s[0] for s in shares])
    tick_share = np.array([s[1] for s in shares])[(tick_t >= t[k0]) & (tick_t < t[k1 - 1])]

    def speed(xy: np.ndarray) -> float:
        """Straight-line speed over the window [m/s]."""
        return float(np.linalg.norm(xy[k1 - 1] - xy[k0]) / max(t[k1 - 1] - t[k0], 1e-9))

    end = "no UHC termination" if uhc is None else f"UHC termination at {t[uhc]:.2f} s"
    end += f", measured {t[k0]:.2f}-{t[k1 - 1]:.2f} s"
    line = (f"{clip} seed {seed}: {end}; his speed {speed(his_com):.2f} m/s, the character's {speed(com):.2f} m/s\n"
            + "".join(f"    {name:10s} {kind.text()}\n" for name, kind in kinds.items())
            + f"    legs' torque: at the limit {np.mean(tick_share >= AT_LIMIT):.1%} of the ticks, "
              f"p95 {np.percentile(tick_share, 95):.2f} of the limit")
    return line, kinds, tick_share


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="CLIP:SEED, e.g. walk:0")
    ap.add_argument("--from", dest="from_s", type=float, default=1.5, help="first time looked at [s]")
    ap.add_argument("--duration", type=float, default=12.0, help="the run's length [s]")
    ap.add_argument("--whole", action="store_true", help="to the end of his clip, past a UHC termination")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    total = {"with his": Kind(), "before his": Kind()}
    shares = []
    for run in args.runs:
        clip, _, seed = run.rpartition(":")
        line, kinds, share = gait_losses(clip, int(seed), args.duration, args.from_s, args.whole)
        print(line, flush=True)
        for name, kind in kinds.items():
            total[name].add(kind)
        shares.append(share)
    every = np.concatenate(shares) if shares else np.zeros(0)
    print(f"all {len(args.runs)} runs:")
    for name, kind in total.items():
        print(f"    {name:10s} {kind.text()}")
    if every.size:
        print(f"    legs' torque: at the limit {np.mean(every >= AT_LIMIT):.1%} of the ticks, "
              f"p95 {np.percentile(every, 95):.2f} of the limit")


if __name__ == "__main__":
    main()

"""How fast an operator can the character keep up with? The built-in walk played faster (prints figures; not a test).

    python benchmarks/keep_up.py [--clip walk] [--speeds 0.8,1.0,1.2,1.4,1.6] [--seeds 0,1,2,3] [--duration 12]

The operator's clip is played at each speed (OperatorConfig.playback_speed: his cadence and his speed over the ground
both scale), by default and with `--follow-path`'s settings (config.follow_path). After the standing lead-in, each
run prints his speed over the ground (his pelvis, scaled to the character as the imitation metrics scale him) and
the character's (its pelvis), both as the straight-line distance over the time [m/s], their ratio, how far along his
path the character went (imitation.path_progress), the UHC termination time [s] and whether it fell: the gait's
speed limit, which ends `--follow-path`'s fast walks by the UHC termination (docs/decisions.md, "Why `--follow-path`'s
walks are slower than his").
"""

from __future__ import annotations

import argparse
import logging

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig, follow_path
from stylesync.metrics import imitation as im
from stylesync.metrics.summary import summarize
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


def _speeds_mps(result, lead_in_s: float) -> tuple[float, float]:
    """His and the character's pelvis speed over the ground after the lead-in: straight-line distance over time."""
    lg = result.log
    t = lg.array("t")
    ch = lg.array("ch_joints")
    ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
    after = np.where(t >= lead_in_s)[0]
    if len(after) < 2:
        return 0.0, 0.0
    a, b = after[0], after[-1]
    span = float(t[b] - t[a])
    return (float(np.hypot(*(ref[b, 0, :2] - ref[a, 0, :2]))) / span,
            float(np.hypot(*(ch[b, 0, :2] - ch[a, 0, :2]))) / span)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="walk")
    ap.add_argument("--speeds", default="0.8,1.0,1.2,1.4,1.6",
                    help="playback speeds, times the clip's, comma-separated")
    ap.add_argument("--seeds", default="0,1,2,3", help="sensor seeds, comma-separated")
    ap.add_argument("--duration", type=float, default=12.0, help="simulated seconds of each run")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    print(f"{'settings':14s} {'speed':>5s} {'seed':>4s} {'his m/s':>8s} {'its m/s':>8s} {'ratio':>5s} "
          f"{'his way':>7s} {'UHC at s':>8s} {'fell':>5s}")
    for label, configure in (("default", None), ("--follow-path", follow_path)):
        for speed in (float(s) for s in args.speeds.split(",")):
            for seed in (int(s) for s in args.seeds.split(",")):
                op = OperatorConfig(clip=args.clip, playback_speed=speed)
                cfg = SessionConfig(duration_s=args.duration, seed=seed, operator=op)
                if configure is not None:
                    cfg = configure(cfg)
                source, _ = builtin_operator(cfg.operator, cfg.clocks, args.duration + 1.0, seed)
                result = Session(cfg, source).run()
                m = summarize(result)
                his, its = _speeds_mps(result, cfg.operator.standing_lead_in_s)
                uhc = m.get("uhc_fall_time_s")
                way = m.get("path_progress")
                print(f"{label:14s} {speed:5.2f} {seed:4d} {his:8.2f} {its:8.2f} {its / max(his, 1e-9):5.2f} "
                      f"{'' if way is None else f'{way:.2f}':>7s} {'' if uhc is None else f'{uhc:.2f}':>8s} "
                      f"{'yes' if result.fell else 'no':>5s}")


if __name__ == "__main__":
    main()

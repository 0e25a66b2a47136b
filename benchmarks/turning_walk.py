"""Does the character turn with its operator? The built-in walk bent into turns (prints figures; not a test).

    python benchmarks/turning_walk.py [--clip walk] [--rates -0.6,-0.3,0,0.3,0.6] [--seeds 0,1] [--duration 12]

The built-in clips go nearly straight (the walk turns 49° in 12 s). Here the operator's path is bent into a turn
at each rate after the lead-in (OperatorConfig.turn_rate_rad_s, sources/turning_path.py: 0.3 rad/s is a half turn
in 10.5 s, 0.6 rad/s a full turn on a circle of about 1.7 m radius), and each run prints: whether it fell, his
turn, the steps (character / operator), the heading error (the character's hip line against his) at the median
and at most over the run after the lead-in and at its end [deg], the root-relative MPJPE [mm] and the UHC
termination time [s].
"""

from __future__ import annotations

import argparse
import logging

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.metrics.imitation import facing_error_deg
from stylesync.metrics.summary import summarize
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="walk")
    ap.add_argument("--rates", default="-0.6,-0.3,0,0.3,0.6", help="turn rates [rad/s], comma-separated")
    ap.add_argument("--seeds", default="0,1", help="sensor seeds, comma-separated")
    ap.add_argument("--duration", type=float, default=12.0, help="simulated seconds of each run")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    for rate in (float(r) for r in args.rates.split(",")):
        for seed in (int(s) for s in args.seeds.split(",")):
            op = OperatorConfig(clip=args.clip, turn_rate_rad_s=rate)
            cfg = SessionConfig(duration_s=args.duration, seed=seed, operator=op)
            source, _ = builtin_operator(op, cfg.clocks, args.duration + 1.0, seed)
            result = Session(cfg, source).run()
            m = summarize(result)
            cols = result.log.columns
            t = np.asarray(cols["t"])
            err = facing_error_deg(np.asarray(cols["ch_joints"]), np.asarray(cols["op_joints"]))
            after = np.abs(err[t >= op.standing_lead_in_s])
            turn_deg = np.degrees(rate * max(float(t[-1]) - op.standing_lead_in_s, 0.0))
            uhc = m.get("uhc_fall_time_s")
            fell = f"yes at {result.fall_time_s:.2f} s" if result.fell else "no"
            print(f"rate {rate:+.2f} rad/s seed {seed}: fell {fell}, "
                  f"his turn {turn_deg:+.0f} deg, steps {m['character_steps']}/{m['operator_steps']}, heading error "
                  f"median {np.median(after):.0f} max {after.max():.0f} end {err[-1]:+.0f} deg, "
                  f"MPJPE root-rel. {m['mpjpe_root_mm']:.0f} mm, UHC termination "
                  f"{'none' if uhc is None else f'{uhc:.2f} s'}", flush=True)


if __name__ == "__main__":
    main()

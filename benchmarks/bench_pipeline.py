"""Speed of the whole pipeline against physics alone, measured in one run (prints figures; not a test).

    python benchmarks/bench_pipeline.py [--clip stand] [--duration 20] [--repeat 3]

Physics alone: the same world and character stepped at the physics rate with zero joint torques (the character
simply falls and lies; contact work is comparable). Whole pipeline: source -> processing -> motion -> control ->
physics, headless, as fast as possible. Both are timed in this process, alternately (--repeat times each), and their
medians and per-pair ratios are printed: the ratio is meaningful on a noisy machine even when the absolute figures
are not.
"""

from __future__ import annotations

import argparse

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.metrics.bench import physics_only_rtf
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="stand")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds of each measurement")
    ap.add_argument("--repeat", type=int, default=3,
                    help="alternating measurements of each (physics alone, pipeline); medians are reported")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, operator=OperatorConfig(clip=args.clip))
    phys_rtfs, rtfs = [], []
    result = None
    for _ in range(max(args.repeat, 1)):  # alternated, so that both see the machine's slow and fast spells alike
        phys_rtfs.append(physics_only_rtf(cfg, args.duration))
        source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
        result = Session(cfg, source).run()
        rtfs.append(result.sim_duration_s / result.wall_duration_s)
    assert result is not None
    phys, rtf = float(np.median(phys_rtfs)), float(np.median(rtfs))
    ratios = [r / p for r, p in zip(rtfs, phys_rtfs, strict=True)]
    ticks = len(result.stage_ms["motion"])
    steps = len(result.stage_ms["physics"])
    print(f"clip {args.clip}, simulated {result.sim_duration_s:.2f} s"
          f"{f' (fell at {result.fall_time_s:.2f} s)' if result.fell else ''}, {ticks} control ticks, "
          f"{steps} physics steps, {len(rtfs)} alternating measurements of each")
    print(f"realtime factor, physics alone:  {phys:6.2f}x median   ({', '.join(f'{x:.2f}' for x in phys_rtfs)})")
    print(f"realtime factor, whole pipeline: {rtf:6.2f}x median   ({', '.join(f'{x:.2f}' for x in rtfs)})")
    print(f"ratio pipeline / physics alone:  {float(np.median(ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in ratios)})")
    print("time per control tick [ms], mean / p99 (last pipeline measurement):")
    per_tick = {k: np.asarray(v) for k, v in result.stage_ms.items()}
    steps_per_tick = steps / max(ticks, 1)
    for name, values in per_tick.items():
        if values.size == 0:
            continue
        scale = steps_per_tick if name in ("torques", "physics") else 1.0  # per-step stages summed over a tick
        print(f"  {name:15s} {values.mean() * scale:7.3f} / {np.percentile(values, 99) * scale:7.3f}"
              f"{f'   ({steps_per_tick:.1f} physics steps per tick)' if scale != 1.0 else ''}")
    tick_total = result.log.array("tick_ms")
    print(f"  {'control tick':15s} {tick_total.mean():7.3f} / {np.percentile(tick_total, 99):7.3f}"
          "   (processing + motion + control update)")


if __name__ == "__main__":
    main()

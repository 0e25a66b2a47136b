"""Speed of the whole pipeline against physics alone, measured in one run (prints figures; not a test).

    python benchmarks/bench_pipeline.py [--clip stand] [--duration 20] [--repeat 3] [--motion-ahead]

Physics alone: the same world and character stepped at the physics rate with zero joint torques (the character
simply falls and lies; contact work is comparable). Whole pipeline: source -> processing -> motion -> control ->
physics, headless, as fast as possible, as `stylesync demo` runs it: the operator side (source, processing, style
features) computed ahead in a second process (prefetch.py). The pipeline is also timed with everything in one
process, and with ``--motion-ahead`` as `stylesync demo --motion-ahead` runs it too: the motion stage on the last
tick's state, computed a tick ahead in a third process (motion_ahead.py; another simulation). All are timed
alternately (--repeat times each), and their medians and per-round ratios are printed: the ratio is meaningful on a
noisy machine even when the absolute figures are not.
"""

from __future__ import annotations

import argparse
import logging

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.metrics.bench import physics_only_rtf
from stylesync.session import Session, SessionResult
from stylesync.sources.builtin_operator import builtin_operator


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="stand")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds of each measurement")
    ap.add_argument("--repeat", type=int, default=3,
                    help="alternating measurements of each (physics alone, pipeline); medians are reported")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--motion-ahead", action="store_true", help="also the pipeline with the motion stage a tick ahead")
    args = ap.parse_args()
    logging.getLogger("stylesync").setLevel(logging.ERROR)  # the runs' warnings (movement bounds) are not measured here
    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, operator=OperatorConfig(clip=args.clip))
    phys_rtfs, rtfs, one_rtfs, ahead_rtfs = [], [], [], []
    result = ahead = None

    def pipeline(prefetch: bool, motion_ahead: bool = False) -> SessionResult:
        run_cfg = cfg.replace(motion_ahead=motion_ahead)
        source, _ = builtin_operator(run_cfg.operator, run_cfg.clocks, run_cfg.duration_s + 1.0, run_cfg.seed)
        session = Session(run_cfg, source)
        session.prefetch_operator = prefetch
        return session.run()

    for _ in range(max(args.repeat, 1)):  # alternated, so that all see the machine's slow and fast spells alike
        phys_rtfs.append(physics_only_rtf(cfg, args.duration))
        one = pipeline(prefetch=False)
        one_rtfs.append(one.sim_duration_s / one.wall_duration_s)
        result = pipeline(prefetch=True)
        rtfs.append(result.sim_duration_s / result.wall_duration_s)
        if args.motion_ahead:
            ahead = pipeline(prefetch=True, motion_ahead=True)
            ahead_rtfs.append(ahead.sim_duration_s / ahead.wall_duration_s)
    assert result is not None
    phys, rtf, one_rtf = float(np.median(phys_rtfs)), float(np.median(rtfs)), float(np.median(one_rtfs))
    ratios = [r / p for r, p in zip(rtfs, phys_rtfs, strict=True)]
    one_ratios = [r / p for r, p in zip(one_rtfs, phys_rtfs, strict=True)]
    ticks = len(result.stage_ms["motion"])
    steps = len(result.stage_ms["physics"])
    print(f"clip {args.clip}, simulated {result.sim_duration_s:.2f} s"
          f"{f' (fell at {result.fall_time_s:.2f} s)' if result.fell else ''}, {ticks} control ticks, "
          f"{steps} physics steps, {len(rtfs)} alternating measurements of each")
    print(f"realtime factor, physics alone:  {phys:6.2f}x median   ({', '.join(f'{x:.2f}' for x in phys_rtfs)})")
    print(f"realtime factor, whole pipeline: {rtf:6.2f}x median   ({', '.join(f'{x:.2f}' for x in rtfs)})"
          f"{'' if result.operator_prefetched else '   (operator side NOT prefetched: see prefetch.py)'}")
    print(f"  ... in one process:            {one_rtf:6.2f}x median   ({', '.join(f'{x:.2f}' for x in one_rtfs)})")
    print(f"ratio pipeline / physics alone:  {float(np.median(ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in ratios)})")
    print(f"  ... in one process:            {float(np.median(one_ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in one_ratios)})")
    if ahead is not None:
        ahead_ratios = [r / p for r, p in zip(ahead_rtfs, phys_rtfs, strict=True)]
        print(f"  ... the motion stage ahead:    {float(np.median(ahead_ratios)):6.2f} median   "
              f"({', '.join(f'{x:.2f}' for x in ahead_ratios)}); {float(np.median(ahead_rtfs)):.2f}x median; "
              f"motion / control update in the main process {np.mean(ahead.stage_ms['motion']):.3f} / "
              f"{np.mean(ahead.stage_ms['control_update']):.3f} ms a tick at the mean")
    print("time per control tick in the main process [ms], mean / p99 (last pipeline measurement):")
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

"""Command line: ``stylesync demo``."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

from stylesync.config import ControlConfig, OperatorConfig, SessionConfig
from stylesync.errors import StylesyncError


def _demo(args: argparse.Namespace) -> int:
    from stylesync.metrics.plots import write_plots, write_strip
    from stylesync.metrics.summary import summarize
    from stylesync.session import Session
    from stylesync.sources.builtin_operator import builtin_operator

    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, gui=args.gui, realtime=args.realtime,
                        operator=OperatorConfig(clip=args.clip),
                        control=ControlConfig(lipm_time_sync=not args.no_lipm))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    result = session.run(render_every_s=max(cfg.duration_s / 8, 0.25))
    metrics = summarize(result)
    metrics["clip"] = args.clip
    metrics["lipm_time_sync"] = not args.no_lipm
    (out / "metrics.json").write_text(json.dumps(metrics, indent=2))
    write_plots(result, out)
    write_strip(session.renders, out / "render_strip.png")
    print(json.dumps({k: metrics[k] for k in ("fell", "fall_time_s", "sim_duration_s", "operator_steps",
                                              "character_steps", "realtime_factor")}))
    print(f"outputs in {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="stylesync", description="Style-preserving humanoid teleoperation")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the built-in operator through the whole pipeline, headless")
    demo.add_argument("--clip", default="walk", help="pybullet_data humanoid3d clip, or 'stand'")
    demo.add_argument("--duration", type=float, default=12.0, help="simulated seconds")
    demo.add_argument("--out", default="out/demo", help="output folder")
    demo.add_argument("--seed", type=int, default=0)
    demo.add_argument("--gui", action="store_true", help="open the PyBullet window")
    demo.add_argument("--realtime", action="store_true", help="pace to the wall clock")
    demo.add_argument("--no-lipm", action="store_true", help="switch the LIPM time-sync compensation off (Eq. 21-23)")
    demo.set_defaults(func=_demo)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return int(args.func(args))
    except StylesyncError as exc:
        print(f"stylesync: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

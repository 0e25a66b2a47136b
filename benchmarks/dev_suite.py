"""The development suite: every shared clip, several sensor seeds, two versions of stylesync in the same run.

    python benchmarks/dev_suite.py --baseline 9e63c3d --seeds 3 --duration 12 --out out/dev_suite

Clips: the humanoid3d clips of pybullet_data and every clip of ../shared/mocap (cmu, cmu-dev, deepmimic), each
with a category (walk, styled walk, uneven, run, jump, kick, arms, acrobatics). Both versions (this checkout's
HEAD and --baseline) are checked out in temporary git worktrees and each run goes through its own interpreter,
alternating versions, two at a time (one per core). A run lasts the clip (at most --duration seconds, the 1 s
standing lead-in of a clip, or the rest after a recorded file, included) through the Kinect sensor model with the
given seed. Per category: runs, clips that could be opened, completion (no fall), runs through the clip (no fall
before the clip's end; a fall in the rest after it counts against completion only), runs without a UHC/PHC
termination, mean fall time, MPJPE (global, root-relative), steps (character / operator) and the median of the
runs' largest transition delays. Nothing is tuned per clip: the same settings for every run. Writes dev_suite.md
and dev_suite.json under --out.
"""

from __future__ import annotations

import argparse
import json
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from versions import REPO, checkouts, probe

SHARED = REPO.parent / "shared" / "mocap"
# Category of each clip, from the clips' READMEs (../shared/mocap/*/README.md) and the humanoid3d clip names.
CATEGORIES = {
    "walk": "walk", "stealthy_walk": "styled walk", "long_humanoid3d_stealthy_walk0": "styled walk",
    "zombie_walk": "styled walk", "jog": "run", "run": "run", "jump": "jump", "kick": "kick", "spinkick": "kick",
    "punch": "arms", "dance_a": "arms", "dance_b": "arms", "spin": "arms", "backflip": "acrobatics",
    "cartwheel": "acrobatics", "crawl": "acrobatics", "getup_facedown": "acrobatics",
    "getup_faceup": "acrobatics", "roll": "acrobatics",
    "02_01": "walk", "131_01": "styled walk", "131_02": "styled walk", "131_03": "jump",
    "02_02": "walk", "05_01": "walk", "06_01": "walk", "07_01": "walk", "07_05": "walk", "07_11": "walk",
    "08_01": "walk", "08_04": "walk", "08_08": "walk", "10_04": "walk", "12_01": "walk", "08_07": "styled walk",
    "03_01": "uneven", "03_02": "uneven", "02_03": "run", "09_01": "run", "09_06": "run", "09_11": "run",
    "02_04": "jump", "13_11": "jump", "13_32": "jump", "13_39": "jump", "13_41": "jump", "jumping_jacks": "jump",
}
ORDER = ("walk", "styled walk", "uneven", "run", "jump", "kick", "arms", "acrobatics")

_PROBE = r'''
import dataclasses, json, logging, sys
logging.disable(logging.CRITICAL)
from stylesync.config import OperatorConfig, SessionConfig
from stylesync.errors import StylesyncError
from stylesync.metrics.summary import summarize
from stylesync.session import Session
from stylesync.sources.registry import open_source
spec, seed, duration = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
try:
    opened = open_source(spec, seed=seed, duration_s=duration)
except StylesyncError as exc:
    print(json.dumps({"error": str(exc)[:200]}))
    raise SystemExit(0)
length = min(duration, float(opened.duration_s or duration))
op = OperatorConfig()
in_motion = spec.startswith(("bvh:", "k4a-json:")) and getattr(op, "start_in_motion", False)
clip_end = length - (min(getattr(op, "rest_after_clip_s", 0.0), length) if in_motion else 0.0)
cfg = SessionConfig(duration_s=length, seed=seed, operator=OperatorConfig(),
                    clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
try:
    result = Session(cfg, opened.source).run()
finally:
    opened.source.close()
m = summarize(result)
keys = ("fell", "fall_time_s", "sim_duration_s", "operator_steps", "character_steps", "state_transition_delay_s",
        "mpjpe_global_mm", "mpjpe_root_mm", "uhc_fall_time_s", "realtime_factor")
print(json.dumps({"clip_end_s": clip_end, **{k: m.get(k) for k in keys}}))
'''


def clip_specs() -> list[tuple[str, str, str]]:
    """(spec, name, category) of every clip of the suite."""
    import pybullet_data

    motions = Path(pybullet_data.getDataPath()) / "data" / "motions"
    out = [(f"builtin:{p.stem.removeprefix('humanoid3d_')}", p.stem.removeprefix("humanoid3d_"))
           for p in sorted(motions.glob("humanoid3d_*.txt"))]
    for folder in ("cmu", "cmu-dev"):
        out += [(f"bvh:{p}", p.stem) for p in sorted((SHARED / folder).glob("*.bvh"))]
    for p in sorted((SHARED / "deepmimic").glob("*.txt")):
        name = p.stem.removeprefix("humanoid3d_")
        out.append((f"deepmimic:{p}", name if not p.stem.startswith("long_") else p.stem))
    return [(spec, name, CATEGORIES.get(name, "other")) for spec, name in out]


def _share(k: int, n: int) -> str:
    return f"{100 * k / n:.0f} % ({k}/{n})" if n else "-"


def _mean(values: list[float], fmt: str) -> str:
    return format(float(np.mean(values)), fmt) if values else "-"


def category_row(cat: str, version: str, rs: list[dict]) -> str:
    """One row of the per-category table (runs that could not be opened are counted, not averaged)."""
    ok = [r for r in rs if "error" not in r]
    n = len(ok)
    complete = sum(not r["fell"] for r in ok)
    through_clip = sum(not r["fell"] or r["fall_time_s"] >= r.get("clip_end_s", np.inf) for r in ok)
    no_uhc = sum(not r["fell"] and r["uhc_fall_time_s"] is None for r in ok)
    falls = [r["fall_time_s"] for r in ok if r["fell"]]
    delays = [r["state_transition_delay_s"]["max"] for r in ok if r["state_transition_delay_s"]["count"]]
    cells = [cat, version, str(len(rs)), str(n), _share(complete, n), _share(through_clip, n), _share(no_uhc, n),
             _mean(falls, ".2f"),
             _mean([r["mpjpe_global_mm"] for r in ok if r.get("mpjpe_global_mm") is not None], ".0f"),
             _mean([r["mpjpe_root_mm"] for r in ok if r.get("mpjpe_root_mm") is not None], ".0f"),
             f"{sum(r['character_steps'] for r in ok)}/{sum(r['operator_steps'] for r in ok)}",
             f"{np.median(delays):.3f}" if delays else "-"]
    return "| " + " | ".join(cells) + " |"


def table(rows: list[dict], versions: list[str]) -> str:
    lines = ["| category | version | runs | opened | complete (no fall) | through the clip (no fall before its end) | "
             "no UHC termination | mean fall time [s] | MPJPE global [mm] | MPJPE root-rel. [mm] | steps char/op | "
             "max delay median [s] |",
             "|" + "---|" * 12]
    for cat in ORDER:
        for v in versions:
            rs = [r for r in rows if r["category"] == cat and r["version"] == v]
            if rs:
                lines.append(category_row(cat, v, rs))
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="9e63c3d", help="git ref of the earlier version ('none': this one only)")
    ap.add_argument("--only", default="", help="comma-separated categories to run (default: all)")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/dev_suite")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    clips = [c for c in clip_specs() if not args.only or c[2] in args.only.split(",")]
    refs = {"this version": "HEAD"}
    if args.baseline != "none":
        refs[f"baseline {args.baseline}"] = args.baseline
    with checkouts(refs) as trees:
        jobs = [(spec, name, cat, seed, v) for spec, name, cat in clips for seed in range(args.seeds) for v in trees]

        def run(job):
            spec, name, cat, seed, v = job
            r = probe(trees[v], _PROBE, spec, str(seed), str(args.duration))
            status = r.get("error") or (f"fell {r['fall_time_s']:.2f} s" if r["fell"] else "complete")
            print(f"{v:>20} {name:>32} seed {seed}: {status}", file=sys.stderr, flush=True)
            return {"clip": name, "spec": spec, "category": cat, "seed": seed, "version": v, **r}

        with ThreadPoolExecutor(max_workers=args.workers) as pool:
            rows = list(pool.map(run, jobs))
    md = table(rows, list(trees))
    (out / "dev_suite.json").write_text(json.dumps(rows, indent=1))
    (out / "dev_suite.md").write_text(md + "\n")
    print(md)


if __name__ == "__main__":
    main()

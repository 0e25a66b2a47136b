"""How long does the character keep a looping motion up? The humanoid3d clips played for a minute (prints figures;
not a test).

    python benchmarks/long_runs.py [--clips walk,run,dance_a] [--seeds 4] [--duration 60] [--follow-path]

The development suite's runs last a clip, at most 12 s (metrics/dev_suite.py); a user who drives the character
live, or plays a long take, asks for more. Each humanoid3d clip of pybullet_data loops (the built-in operator, as
`stylesync demo` plays it, through the Kinect sensor model with each seed) for ``--duration`` seconds with the
suite's settings (dev_suite.run_clip), two runs at a time. Per clip: the runs that stand to the end, each fall's
time [s], his steps and the character's, and the median time of the UHC termination [s]; then the falls per minute
of motion over all runs (the fall rate a long session sees).
"""

from __future__ import annotations

import argparse
import statistics
from concurrent.futures import ProcessPoolExecutor

from stylesync.metrics.dev_suite import FOLLOW_PATH_VERSION, clip_specs, run_clip

# The looping humanoid3d clips of the suite that are not acrobatics (its walk, run, jump, kick and arm categories)
CLIPS = tuple(name for _, name, category in clip_specs(None) if category != "acrobatics")


def _run(job: tuple[str, int, float, str]) -> tuple[str, int, dict]:
    clip, seed, duration_s, version = job
    return clip, seed, run_clip(f"builtin:{clip}", seed, duration_s, version)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clips", default=",".join(CLIPS), help="humanoid3d clip names, comma-separated")
    ap.add_argument("--seeds", type=int, default=4, help="sensor seeds 0 .. N-1")
    ap.add_argument("--duration", type=float, default=60.0, help="simulated seconds of each run")
    ap.add_argument("--follow-path", action="store_true", help="with --follow-path's settings (config.follow_path)")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    version = FOLLOW_PATH_VERSION if args.follow_path else "stylesync"
    clips = [c for c in args.clips.split(",") if c]
    jobs = [(clip, seed, args.duration, version) for clip in clips for seed in range(args.seeds)]
    rows: dict[str, list[tuple[int, dict]]] = {clip: [] for clip in clips}
    with ProcessPoolExecutor(args.workers) as pool:
        for clip, seed, result in pool.map(_run, jobs):
            rows[clip].append((seed, result))
    print(f"{len(jobs)} runs of {args.duration:.0f} s ({version}), seeds 0-{args.seeds - 1}")
    print(f"{'clip':10s} {'stand':>7s}  {'falls at [s]':32s} {'steps his / its':>16s} {'UHC median [s]':>15s}")
    falls, seconds = 0, 0.0
    for clip, results in rows.items():
        fell = [r["fall_time_s"] for _, r in results if r.get("fell")]
        falls += len(fell)
        seconds += sum(r["fall_time_s"] if r.get("fell") else r["sim_duration_s"] for _, r in results)
        uhc = [r["uhc_fall_time_s"] for _, r in results if r.get("uhc_fall_time_s") is not None]
        his = sum(r["operator_steps"] or 0 for _, r in results)
        its = sum(r["character_steps"] or 0 for _, r in results)
        times = ", ".join(f"{t:.1f}" for t in fell)
        print(f"{clip:10s} {len(results) - len(fell):3d} / {len(results):<3d} {times:32s} "
              f"{his:7d} / {its:<7d} {statistics.median(uhc) if uhc else float('nan'):15.2f}")
    print(f"falls per minute of motion: {60.0 * falls / max(seconds, 1e-9):.3f} ({falls} falls in {seconds:.0f} s)")


if __name__ == "__main__":
    main()

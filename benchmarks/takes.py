"""Recorded takes of any length, as users bring them, run as the development suite runs a clip (prints figures; not a
test).

    python benchmarks/takes.py PATH [PATH ...] [--window 15] [--seeds 2] [--workers 2] [--whole]

PATH: BVH files, or folders searched for them. Each take is cut into windows of ``--window`` seconds (the header as it
is, the window's frames copied into a temporary file; a last, shorter window is left out), and each window runs with
each sensor seed as the development suite runs a clip (``metrics.dev_suite.run_clip``: the Kinect sensor model, the
window's first ``--window`` - 3 s, then the 3 s rest), by default and with `--follow-path`. ``--whole`` runs each take
whole instead, to its end and the rest. Prints per mode: the runs, how many complete (no fall), how many without a UHC
termination (the mean joint distance to him, scaled, above 0.5 m) and how many terminate within the first second,
the median termination time, the global and root-relative MPJPE and the share of his way at the median, the steps
(character / operator), and each fall (docs/decisions.md, "Other sources' files").
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from stylesync.metrics.dev_suite import FOLLOW_PATH_VERSION, run_clip

WHOLE_S = 86400.0  # a take run whole: at most a day [s]


def windows(take: Path, window_s: float, folder: Path) -> list[Path]:
    """``take`` cut into files of ``window_s`` seconds in ``folder`` (its header, then the window's frames)."""
    head, motion = take.read_text(errors="replace").split("MOTION", 1)
    lines = [ln for ln in motion.splitlines() if ln.strip()]
    frame_time_s = float(lines[1].split(":", 1)[1])
    frames = lines[2:]
    n = max(1, round(window_s / frame_time_s))
    out = []
    for k, first in enumerate(range(0, len(frames) - n + 1, n)):
        path = folder / f"{take.stem}_{k:03d}.bvh"
        path.write_text(f"{head}MOTION\nFrames: {n}\nFrame Time: {frame_time_s}\n" + "\n".join(frames[first:first + n])
                        + "\n")
        out.append(path)
    return out


def _run(job: tuple[str, int, float, str]) -> dict:
    spec, seed, duration_s, version = job
    return {"clip": Path(spec[4:]).stem, "seed": seed, "version": version, **run_clip(spec, seed, duration_s, version)}


def summary(rows: list[dict]) -> str:
    """One line of figures over ``rows`` (run_clip's results, with "clip" and "seed")."""
    ok = [r for r in rows if "error" not in r]
    complete = [r for r in ok if not r["fell"]]
    uhc = [r["uhc_fall_time_s"] for r in ok if r["uhc_fall_time_s"] is not None]
    way = [r["path_progress"] for r in ok if r["path_progress"] is not None]

    def median(values: list[float | None], fmt: str) -> str:
        known = [v for v in values if v is not None]  # a run too short for a figure has none
        return format(statistics.median(known), fmt) if known else "-"

    mpjpe_global = median([r["mpjpe_global_mm"] for r in ok], ".0f")
    mpjpe_root = median([r["mpjpe_root_mm"] for r in ok], ".0f")
    return (f"{len(rows)} runs ({len(rows) - len(ok)} not opened), {len(complete)} complete, "
            f"{sum(r['uhc_fall_time_s'] is None for r in complete)} without a UHC termination "
            f"({sum(t < 1.0 for t in uhc)} within 1 s; median {median(uhc, '.1f')} s), MPJPE global {mpjpe_global} mm"
            f" / root {mpjpe_root} mm, his way {median(way, '.2f')}, steps {sum(r['character_steps'] for r in ok)}/"
            f"{sum(r['operator_steps'] for r in ok)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="+", type=Path)
    ap.add_argument("--window", type=float, default=15.0, help="window length [s]")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--whole", action="store_true", help="each take whole, not cut into windows")
    args = ap.parse_args()
    takes = sorted(f for p in args.paths for f in ([p] if p.is_file() else p.rglob("*.bvh")))
    with tempfile.TemporaryDirectory() as tmp:
        clips = takes if args.whole else [w for t in takes for w in windows(t, args.window, Path(tmp))]
        duration_s = WHOLE_S if args.whole else args.window
        print(f"{len(takes)} takes, {len(clips)} clips, seeds 0-{args.seeds - 1}")
        for version in ("stylesync", FOLLOW_PATH_VERSION):
            jobs = [(f"bvh:{c}", seed, duration_s, version) for c in clips for seed in range(args.seeds)]
            with ProcessPoolExecutor(args.workers) as pool:
                rows = list(pool.map(_run, jobs))
            print(f"{version:>24}: {summary(rows)}")
            print_falls(rows)


def print_falls(rows: list[dict]) -> None:
    """Each run of ``rows`` that was not opened or fell, one line each."""
    for r in rows:
        if r.get("error"):
            print(f"{'':>26}{r['clip']} seed {r['seed']}: not opened: {r['error']}")
        elif r["fell"]:
            print(f"{'':>26}{r['clip']} seed {r['seed']}: fell at {r['fall_time_s']:.2f} s "
                  f"(its clip ends at {r['clip_end_s']:.2f} s; {r['fall_reason']})")


if __name__ == "__main__":
    main()

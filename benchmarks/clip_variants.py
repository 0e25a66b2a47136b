"""The shared clips as a user might bring them differently, run as the development suite runs a clip (prints figures;
not a test).

    python benchmarks/clip_variants.py [--variants reversed,speed0.5,speed1.5] [--categories "walk,styled walk,uneven"]
                                       [--seeds 2] [--workers 2] [--follow-path] [--mocap ../shared/mocap]

Each recorded clip of the chosen categories of ``../shared/mocap`` (BVH and DeepMimic files; the built-in humanoid3d
clips are the dev suite's own and are not varied) is written to a temporary file as a variant: ``reversed`` (its frames
in reverse order: the same person walking backwards, facing forwards; a jump or a kick played back to front), or
``speedX`` (its frame time divided by X: the same motion X times as fast, cadence and speed). Each variant runs with
each sensor seed as the development suite runs a clip (``metrics.dev_suite.run_clip``), by default, and with
``--follow-path`` also with `--follow-path`. Prints per variant and mode the figures of ``takes.summary`` and each fall
(docs/decisions.md, "A backward walk").
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from takes import print_falls, summary

from stylesync.metrics.dev_suite import FOLLOW_PATH_VERSION, clip_specs, run_clip

DURATION_S = 12.0  # as the development suite


def bvh_variant(source: Path, target: Path, reverse: bool, speed: float) -> None:
    """``source`` (BVH) written to ``target`` with its frames reversed and/or its frame time divided by ``speed``."""
    head, motion = source.read_text(errors="replace").split("MOTION", 1)
    lines = [ln for ln in motion.splitlines() if ln.strip()]
    frame_time_s = float(lines[1].split(":", 1)[1]) / speed
    frames = lines[2:][::-1] if reverse else lines[2:]
    target.write_text(f"{head}MOTION\nFrames: {len(frames)}\nFrame Time: {frame_time_s:.8f}\n"
                      + "\n".join(frames) + "\n")


def deepmimic_variant(source: Path, target: Path, reverse: bool, speed: float) -> None:
    """``source`` (DeepMimic) written to ``target`` with its poses reversed (each frame's duration kept in its place:
    the last frame's is zero) and/or its durations divided by ``speed``."""
    clip = json.loads(source.read_text())
    frames = [list(f) for f in clip["Frames"]]
    durations = [f[0] / speed for f in frames]
    if reverse:
        frames = frames[::-1]
    for frame, duration in zip(frames, durations, strict=True):
        frame[0] = duration
    target.write_text(json.dumps({**clip, "Frames": frames}))


def parse_variant(variant: str) -> tuple[bool, float]:
    """(reversed, speed) of a variant's name, ``reversed`` or ``speedX`` with X > 0; ValueError otherwise."""
    if variant == "reversed":
        return True, 1.0
    speed = float(variant.removeprefix("speed")) if variant.startswith("speed") else math.nan
    if not speed > 0.0:
        raise ValueError(f"unknown variant '{variant}': reversed or speedX with X > 0")
    return False, speed


def variant_specs(mocap: Path, categories: set[str], variant: str, folder: Path) -> list[tuple[str, str]]:
    """(spec, name) of each recorded clip of ``categories`` as ``variant``, written into ``folder``."""
    reverse, speed = parse_variant(variant)
    out = []
    for spec, name, category in clip_specs(mocap):
        kind, _, path = spec.partition(":")
        if category not in categories or kind not in ("bvh", "deepmimic"):
            continue
        source = Path(path)
        target = folder / f"{variant}_{source.name}"
        (bvh_variant if kind == "bvh" else deepmimic_variant)(source, target, reverse, speed)
        out.append((f"{kind}:{target}", name))
    return out


def _run(job: tuple[str, str, int, str]) -> dict:
    spec, name, seed, version = job
    return {"clip": name, "seed": seed, "version": version, **run_clip(spec, seed, DURATION_S, version)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default="reversed", help="comma-separated: reversed, speedX (X > 0)")
    ap.add_argument("--categories", default="walk,styled walk,uneven", help="comma-separated dev-suite categories")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--follow-path", action="store_true", help="also with --follow-path")
    ap.add_argument("--mocap", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "mocap")
    args = ap.parse_args()
    if not args.mocap.is_dir():
        raise SystemExit(f"no shared mocap folder at {args.mocap} (--mocap)")
    variants = [v.strip() for v in args.variants.split(",") if v.strip()]
    for v in variants:
        try:
            parse_variant(v)
        except ValueError as exc:
            raise SystemExit(f"unknown variant '{v}': reversed or speedX with X > 0") from exc
    categories = {c.strip() for c in args.categories.split(",")}
    versions = ("stylesync", FOLLOW_PATH_VERSION) if args.follow_path else ("stylesync",)
    with tempfile.TemporaryDirectory() as tmp:
        for variant in variants:
            clips = variant_specs(args.mocap, categories, variant, Path(tmp))
            print(f"{variant}: {len(clips)} clips ({', '.join(sorted(categories))}), seeds 0-{args.seeds - 1}")
            for version in versions:
                jobs = [(spec, name, seed, version) for spec, name in clips for seed in range(args.seeds)]
                with ProcessPoolExecutor(args.workers) as pool:
                    rows = list(pool.map(_run, jobs))
                print(f"{version:>24}: {summary(rows)}")
                print_falls(rows)


if __name__ == "__main__":
    main()

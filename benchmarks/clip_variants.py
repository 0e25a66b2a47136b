"""The shared clips as a user might bring them differently, run as the development suite runs a clip (prints figures;
not a test).

    python benchmarks/clip_variants.py [--variants reversed,speed0.5,speed1.5] [--categories "walk,styled walk,uneven"]
                                       [--seeds 2] [--workers 2] [--follow-path] [--mocap ../shared/mocap]

Each recorded clip of the chosen categories of ``../shared/mocap`` (BVH and DeepMimic files; the built-in humanoid3d
clips are the dev suite's own and are not varied) is written to a temporary file as a variant: ``reversed`` (its frames
in reverse order: the same person walking backwards, facing forwards; a jump or a kick played back to front), ``speedX``
(its frame time divided by X: the same motion X times as fast, cadence and speed), ``fromX`` (its first X seconds cut
off, BVH only: the same take started at another phase of its motion), ``fpsN`` (every k-th frame kept, k the nearest to
the clip's rate over N: the same take captured at about N frames a second), ``statureX`` (BVH only: every offset and
position channel times X, a person X times as tall moving alike), ``yawX`` (BVH only, a Y-up file: the take turned X
degrees about the vertical through the origin, its root's position and rotation channels turned, a walk in another
direction of the room) or ``turnX`` (BVH only, a Y-up file: the take bent into a turn of X degrees a second, each
frame's root displacement over the ground and its rotation turned by the angle reached then: a straight walk becomes a
circle, a planted foot sliding a little, as `--turn-rate` bends the built-in walk). Each variant runs with each sensor
seed as the development suite runs a clip (``metrics.dev_suite.run_clip``), by default, and with ``--follow-path`` also
with `--follow-path`. Prints per variant and mode the figures of ``takes.summary`` and each fall (docs/decisions.md, "A
backward walk").
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation
from takes import print_falls, summary

from stylesync.metrics.dev_suite import FOLLOW_PATH_VERSION, clip_specs, run_clip

DURATION_S = 12.0  # as the development suite


@dataclass(frozen=True)
class Variant:
    """How a clip is changed: frames reversed, frame time divided by ``speed``, the first ``cut_s`` seconds cut off,
    every ``every``-th frame kept at about ``fps`` frames a second (None: all), lengths times ``stature``."""
    reverse: bool = False
    speed: float = 1.0
    cut_s: float = 0.0
    fps: float | None = None
    stature: float = 1.0
    yaw_deg: float = 0.0
    turn_deg_s: float = 0.0

    @property
    def bvh_only(self) -> bool:
        """A stature, a cut start or a turn: not for DeepMimic clips (the humanoid's own skeleton; a looping
        cycle; the clip's own root frame)."""
        return self.stature != 1.0 or self.cut_s > 0.0 or self.yaw_deg != 0.0 or self.turn_deg_s != 0.0


def _kept(durations_s: list[float], v: Variant) -> list[int]:
    """Indices of the frames a variant keeps, of frames lasting ``durations_s`` [s] each (at their recorded pace)."""
    start, t = 0, 0.0
    while start < len(durations_s) - 1 and t + 1e-9 < v.cut_s:
        t += durations_s[start]
        start += 1
    step = 1 if v.fps is None else max(1, round(1.0 / (v.fps * max(durations_s[0], 1e-9))))
    return list(range(start, len(durations_s), step))


def _position_channels(head: str) -> list[int]:
    """Indices, in a BVH frame line, of the channels that are positions (every joint's, in header order)."""
    out, k = [], 0
    for line in head.splitlines():
        words = line.split()
        if words and words[0] == "CHANNELS":
            names = words[2:2 + int(words[1])]
            out += [k + i for i, name in enumerate(names) if name.lower().endswith("position")]
            k += len(names)
    return out


def _root_channels(head: str) -> list[str]:
    """The root joint's channel names, in order."""
    for line in head.splitlines():
        words = line.split()
        if words and words[0] == "CHANNELS":
            return words[2:2 + int(words[1])]
    raise ValueError("no CHANNELS line")


def _turned(frame: list[str], channels: list[str], yaw_deg: float, position: np.ndarray | None = None) -> list[str]:
    """A BVH frame's values (Y-up) with its root turned ``yaw_deg`` about the vertical: the position channels
    rotated (or set to ``position``, file units), the root's rotation left-multiplied by the turn (its channels are
    intrinsic rotations in order)."""
    turn = Rotation.from_euler("y", yaw_deg, degrees=True)
    pos = [channels.index(f"{a}position") for a in "XYZ"]
    angles = [k for k, name in enumerate(channels) if name.endswith("rotation")]
    order = "".join(channels[k][0].upper() for k in angles)
    out = list(frame)
    moved = turn.apply([float(frame[k]) for k in pos]) if position is None else position
    for k, v in zip(pos, moved, strict=True):
        out[k] = f"{v:.6f}"
    root = turn * Rotation.from_euler(order, [float(frame[k]) for k in angles], degrees=True)
    with warnings.catch_warnings():  # at a gimbal lock one of the equal sets of angles: the rotation is the same
        warnings.simplefilter("ignore", UserWarning)
        euler = root.as_euler(order, degrees=True)
    for k, v in zip(angles, euler, strict=True):
        out[k] = f"{v:.6f}"
    return out


def _bent(frames: list[str], channels: list[str], deg_per_frame: float) -> list[str]:
    """BVH frames (Y-up) bent into a turn: frame k's root turned by k ``deg_per_frame`` about the vertical, its
    displacement over the ground since the last frame turned by the same angle and added up (the height as
    recorded)."""
    pos = [channels.index(f"{a}position") for a in "XYZ"]
    values = [f.split() for f in frames]
    recorded = np.array([[float(f[k]) for k in pos] for f in values])
    at = recorded[0].copy()
    out = []
    for k, f in enumerate(values):
        if k:
            step = Rotation.from_euler("y", k * deg_per_frame, degrees=True).apply(recorded[k] - recorded[k - 1])
            at = at + step
            at[1] = recorded[k, 1]
        out.append(" ".join(_turned(f, channels, k * deg_per_frame, at)))
    return out


def _scaled_offsets(head: str, factor: float) -> str:
    """A BVH header with every OFFSET times ``factor``."""
    lines = []
    for line in head.splitlines():
        words = line.split()
        if words and words[0] == "OFFSET":
            indent = line[:len(line) - len(line.lstrip())]
            line = indent + "OFFSET " + " ".join(f"{float(w) * factor:.6f}" for w in words[1:])
        lines.append(line)
    return "\n".join(lines) + "\n"


def bvh_variant(source: Path, target: Path, v: Variant) -> bool:
    """``source`` (BVH) written to ``target`` as the variant ``v``; False (nothing written) where the cut leaves
    fewer than two frames."""
    head, motion = source.read_text(errors="replace").split("MOTION", 1)
    lines = [ln for ln in motion.splitlines() if ln.strip()]
    recorded_s = float(lines[1].split(":", 1)[1])
    frames = lines[2:]
    kept = _kept([recorded_s] * len(frames), v)
    if len(kept) < 2:
        return False
    frames = [frames[k] for k in kept]
    frame_time_s = recorded_s * (kept[1] - kept[0]) / v.speed
    if v.stature != 1.0:
        positions = set(_position_channels(head))
        head = _scaled_offsets(head, v.stature)
        frames = [" ".join(f"{float(w) * v.stature:.6f}" if i in positions else w for i, w in enumerate(f.split()))
                  for f in frames]
    if v.yaw_deg != 0.0:
        channels = _root_channels(head)
        frames = [" ".join(_turned(f.split(), channels, v.yaw_deg)) for f in frames]
    if v.turn_deg_s != 0.0:
        frames = _bent(frames, _root_channels(head), v.turn_deg_s * frame_time_s)
    frames = frames[::-1] if v.reverse else frames
    target.write_text(f"{head}MOTION\nFrames: {len(frames)}\nFrame Time: {frame_time_s:.8f}\n"
                      + "\n".join(frames) + "\n")
    return True


def deepmimic_variant(source: Path, target: Path, v: Variant) -> bool:
    """``source`` (DeepMimic) written to ``target`` as the variant ``v`` (not :attr:`Variant.bvh_only`): poses
    reversed (each frame's duration kept in its place: the last frame's is zero),
    durations divided by ``speed``, a kept frame lasting until the next kept one."""
    clip = json.loads(source.read_text())
    frames = [list(f) for f in clip["Frames"]]
    kept = _kept([f[0] for f in frames], v)
    durations = [sum(f[0] for f in frames[a:b]) / v.speed for a, b in zip(kept, kept[1:] + [len(frames)], strict=True)]
    frames = [frames[k] for k in kept]
    if v.reverse:
        frames = frames[::-1]
    for frame, duration in zip(frames, durations, strict=True):
        frame[0] = duration
    target.write_text(json.dumps({**clip, "Frames": frames}))
    return True


VARIANT_HELP = ("reversed, speedX (X > 0), fromX (X >= 0 s), fpsN (N > 0), statureX (X > 0), yawX (X deg), "
                "turnX (X deg/s)")


def parse_variant(variant: str) -> Variant:
    """The variant of a name (VARIANT_HELP); ValueError otherwise."""
    if variant == "reversed":
        return Variant(reverse=True)
    for prefix, field in (("speed", "speed"), ("from", "cut_s"), ("fps", "fps"), ("stature", "stature"),
                          ("yaw", "yaw_deg"), ("turn", "turn_deg_s")):
        if variant.startswith(prefix):
            try:
                value = float(variant.removeprefix(prefix))
            except ValueError:
                value = math.nan
            signed = field in ("yaw_deg", "turn_deg_s")  # any finite angle or rate
            if value > 0.0 or (field == "cut_s" and value == 0.0) or (signed and math.isfinite(value)):
                return Variant(**{field: value})
    raise ValueError(f"unknown variant '{variant}': {VARIANT_HELP}")


def variant_specs(mocap: Path, categories: set[str], variant: str, folder: Path) -> list[tuple[str, str]]:
    """(spec, name) of each recorded clip of ``categories`` as ``variant``, written into ``folder`` (a clip the
    variant leaves fewer than two frames of is left out)."""
    v = parse_variant(variant)
    out = []
    for spec, name, category in clip_specs(mocap):
        kind, _, path = spec.partition(":")
        if category not in categories or kind not in ("bvh", "deepmimic") or (kind != "bvh" and v.bvh_only):
            continue
        source = Path(path)
        target = folder / f"{variant}_{source.name}"
        if (bvh_variant if kind == "bvh" else deepmimic_variant)(source, target, v):
            out.append((f"{kind}:{target}", name))
    return out


def _run(job: tuple[str, str, int, str]) -> dict:
    spec, name, seed, version = job
    return {"clip": name, "seed": seed, "version": version, **run_clip(spec, seed, DURATION_S, version)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default="reversed", help=f"comma-separated: {VARIANT_HELP}")
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
            raise SystemExit(str(exc)) from exc
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

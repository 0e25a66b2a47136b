"""Fuzz targets: every parser and boundary of stylesync, fed mutated inputs.

Each target takes bytes (or, for the command line, a list of arguments) and calls the code a user's input reaches.
The only allowed outcomes are a normal return or a :class:`~stylesync.errors.StylesyncError` (the one-line error
a user sees; the command line's ``SystemExit(2)``). Anything else is a defect.

Inputs are mutations of valid seeds (structure-aware: numbers replaced by extreme values, lines deleted,
duplicated or swapped, truncation, random bytes), made by :func:`mutate` from a ``random.Random``: the long pass
(run.py) draws them from seeded generators, the tests (tests/test_fuzz.py) through hypothesis.
"""

from __future__ import annotations

import json
import random
import re
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pybullet_data

from stylesync.errors import StylesyncError

MOTIONS = Path(pybullet_data.getDataPath()) / "data" / "motions"
EXTREME_NUMBERS = ["nan", "NaN", "inf", "-inf", "1e300", "-1e300", "1e-300", "0", "-0", "-1", "1e9", "-1e9",
                   "99999999999999999999999", "0.0000001", "1e308", "2", "3", "1e-9", "'", '"', ""]
NUMBER = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")


def mutate(seed: bytes, rng: random.Random, rounds: int | None = None) -> bytes:
    """A mutation of ``seed``: 1-4 rounds of number, line or byte edits."""
    data = seed
    for _ in range(rounds if rounds is not None else rng.randint(1, 4)):
        kind = rng.random()
        if kind < 0.4:  # a number replaced by an extreme value
            numbers = list(NUMBER.finditer(data))
            if numbers:
                m = rng.choice(numbers)
                data = data[:m.start()] + rng.choice(EXTREME_NUMBERS).encode() + data[m.end():]
        elif kind < 0.65:  # line edits
            lines = data.split(b"\n")
            if len(lines) > 1:
                i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
                op = rng.randrange(4)
                if op == 0:
                    del lines[i]
                elif op == 1:
                    lines.insert(j, lines[i])
                elif op == 2:
                    lines[i], lines[j] = lines[j], lines[i]
                else:
                    lines[i] = lines[i][: rng.randrange(len(lines[i]) + 1)]
                data = b"\n".join(lines)
        elif kind < 0.8:  # truncation
            data = data[: rng.randrange(len(data) + 1)]
        elif kind < 0.95:  # random bytes somewhere
            at = rng.randrange(len(data) + 1)
            data = data[:at] + bytes(rng.randrange(256) for _ in range(rng.randint(1, 8))) + data[at:]
        else:  # a block repeated (sizes and counts that disagree)
            if data:
                a = rng.randrange(len(data))
                b = min(len(data), a + rng.randint(1, 200))
                data = data[:b] + data[a:b] * rng.randint(1, 20) + data[b:]
    return data


_SKELETON = ("Hips", (0, 0, 0), [
    ("Spine", (0, 10, 0), [("Neck", (0, 30, 0), [("Head", (0, 10, 0), [])]),
                           ("LeftArm", (15, 25, 0), [("LeftForeArm", (25, 0, 0), [("LeftHand", (25, 0, 0), [])])]),
                           ("RightArm", (-15, 25, 0), [("RightForeArm", (-25, 0, 0),
                                                        [("RightHand", (-25, 0, 0), [])])])]),
    ("LeftUpLeg", (10, 0, 0), [("LeftLeg", (0, -45, 0), [("LeftFoot", (0, -42, 0), [])])]),
    ("RightUpLeg", (-10, 0, 0), [("RightLeg", (0, -45, 0), [("RightFoot", (0, -42, 0), [])])])])


def _bvh_seed() -> bytes:
    """A small BVH in the usual layout (CMU-like names, cm, Y up): 17 joints, 3 frames."""
    lines: list[str] = ["HIERARCHY"]
    count = [0]

    def joint(node, depth: int, root: bool) -> None:
        name, offset, children = node
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if root else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {offset[0]} {offset[1]} {offset[2]}")
        if root:
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
            count[0] += 6
        else:
            lines.append(f"{pad}  CHANNELS 3 Zrotation Xrotation Yrotation")
            count[0] += 3
        for child in children:
            joint(child, depth + 1, False)
        if not children:
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET 0 -5 10", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    joint(_SKELETON, 0, True)
    lines += ["MOTION", "Frames: 3", "Frame Time: 0.0333333"]
    for k in range(3):
        values = [0.0] * count[0]
        values[1] = 92.0
        values[0] = float(k)
        values[7] = 3.0 * k
        lines.append(" ".join(f"{v:g}" for v in values))
    return ("\n".join(lines) + "\n").encode()


def _k4a_seed() -> bytes:
    from stylesync.sources.human_model import HumanModel
    from stylesync.sources.k4abt_json import write_k4abt_json

    h = HumanModel()
    frames = [h.frame_from_pose(k / 30, np.array([0.0, 0.0, h.hip_height_m]), {}) for k in range(3)]
    with tempfile.TemporaryDirectory() as tmp:
        write_k4abt_json(frames, Path(tmp) / "k.json")
        return (Path(tmp) / "k.json").read_bytes()


def _deepmimic_seed() -> bytes:
    data = json.loads((MOTIONS / "humanoid3d_walk.txt").read_text())
    data["Frames"] = data["Frames"][:3]
    return json.dumps(data).encode()


def _session_seed() -> bytes:
    from stylesync.config import OperatorConfig, SessionConfig
    from stylesync.export.session_file import SessionRecorder
    from stylesync.session import Session
    from stylesync.sources.builtin_operator import builtin_operator

    cfg = SessionConfig(duration_s=0.05, operator=OperatorConfig(clip="walk"))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, 1.0, 0)
    session = Session(cfg, source)
    session.prefetch_operator = False
    with tempfile.TemporaryDirectory() as tmp:
        recorder = SessionRecorder(Path(tmp) / "session.jsonl", cfg, session)
        session.on_tick = recorder.tick
        session.run()
        recorder.close({"fell": False})
        session.release_engine()
        return (Path(tmp) / "session.jsonl").read_bytes()


def _ply_seed() -> bytes:
    points = "\n".join(f"{x} {y} {z}" for x, y, z in np.random.default_rng(0).random((20, 3)))
    return (b"ply\nformat ascii 1.0\nelement vertex 20\nproperty float x\nproperty float y\nproperty float z\n"
            b"end_header\n" + points.encode() + b"\n")


def _npy_seed() -> bytes:
    import io

    buf = io.BytesIO()
    np.save(buf, np.random.default_rng(0).random((20, 3)))
    return buf.getvalue()


def _vmc_seed() -> bytes:
    from stylesync.sources.human_model import HumanModel
    from stylesync.sources.vmc import VmcSender, osc_bundle

    h = HumanModel()
    frame = h.frame_from_pose(0.0, np.array([0.0, 0.0, h.hip_height_m]), {})
    return osc_bundle(VmcSender("127.0.0.1", 9).messages(frame)).dgram


class FileTarget:
    """A parser of files: the mutated bytes are written to a file with ``suffix`` and ``call`` is given its path."""

    def __init__(self, name: str, suffix: str, seed: Callable[[], bytes], call: Callable[[Path], object]):
        self.name, self.suffix, self._seed, self.call = name, suffix, seed, call
        self._seed_bytes: bytes | None = None
        self._dir = tempfile.TemporaryDirectory(prefix=f"stylesync-fuzz-{name}-")

    @property
    def seed(self) -> bytes:
        if self._seed_bytes is None:
            self._seed_bytes = self._seed()
        return self._seed_bytes

    def __call__(self, data: bytes) -> bool:
        """True: a clean error (StylesyncError); False: accepted."""
        path = Path(self._dir.name) / f"input{self.suffix}"
        path.write_bytes(data)
        try:
            self.call(path)
        except StylesyncError:
            return True
        return False


def _bvh(path: Path) -> None:
    from stylesync.sources.bvh import BvhRecording

    rec = BvhRecording(path)
    rec.performer.frame_at(0.5 * rec.performer.duration_s)


def _k4a(path: Path) -> None:
    from stylesync.sources.k4abt_json import K4abtRecording

    K4abtRecording(path)


def _deepmimic(path: Path) -> None:
    from stylesync.sources.deepmimic_clip import DeepMimicClip

    DeepMimicClip.load(path)


def _joint_map(path: Path) -> None:
    from stylesync.sources.bvh import load_joint_map

    load_joint_map(path)


def _point_cloud(path: Path) -> None:
    from stylesync.processing.point_cloud_volume import load_point_cloud

    load_point_cloud(path)


def _session(path: Path) -> None:
    from stylesync.export.replay import resample_ticks
    from stylesync.export.session_file import read_session

    resample_ticks(read_session(path), 60.0)


class VmcTarget:
    """OSC/VMC datagrams handed to the VMC source's packet handler (no socket)."""

    name = "vmc"

    def __init__(self) -> None:
        self._source = None
        self._seed: bytes | None = None

    @property
    def seed(self) -> bytes:
        if self._seed is None:
            self._seed = _vmc_seed()
        return self._seed

    def __call__(self, data: bytes) -> bool:
        """True: the packet was rejected (counted by the source); False: accepted."""
        if self._source is None:
            from stylesync.sources.vmc import VmcSource

            self._source = VmcSource("127.0.0.1", 0, max_queue=4)
        before = self._source.rejected_frames
        self._source._on_packet(data)
        return self._source.rejected_frames > before

    def close(self) -> None:
        """Stop the source's listener thread."""
        if self._source is not None:
            self._source.close()
            self._source = None


class CliTarget:
    """The command line's parser, given mutated argument lists (parsing only: nothing is run)."""

    name = "cli"
    SEEDS = [["demo", "--duration", "3", "--seed", "1", "--out", "out/x"],
             ["run", "--source", "bvh:x.bvh", "--duration", "5", "--viewer-port", "8080", "--stream-timeout", "2"],
             ["measure", "--source", "builtin:walk", "--mass", "70"],
             ["replay", "x.jsonl", "--speed", "0.5", "--viewer-hz", "20"],
             ["bench", "--suite", "dev", "--seeds", "2", "--workers", "2"],
             ["batch", "clips", "--seeds", "3", "--max-retries", "1", "--duration", "4"]]
    seed = b"\x00".join(" ".join(s).encode() for s in SEEDS)

    def __init__(self) -> None:
        from stylesync.cli import build_parser

        self._parser = build_parser()

    def __call__(self, data: bytes) -> bool:
        """True: the parser refused the arguments (exit 2, one line); False: accepted."""
        text = data.decode("utf-8", errors="replace").replace("\x00", "\n")
        argv = text.split("\n")[0].split(" ")
        try:
            self._parser.parse_args(argv)
        except SystemExit as exc:
            if exc.code not in (0, 2):  # 0: --help
                raise
            return exc.code == 2
        return False


def all_targets() -> list:
    return [FileTarget("bvh", ".bvh", _bvh_seed, _bvh), FileTarget("k4a-json", ".json", _k4a_seed, _k4a),
            FileTarget("deepmimic", ".txt", _deepmimic_seed, _deepmimic),
            FileTarget("joint-map", ".json", lambda: json.dumps({"PELVIS": "Hips", "KNEE_LEFT": "LeftLeg"}).encode(),
                       _joint_map),
            FileTarget("ply", ".ply", _ply_seed, _point_cloud), FileTarget("npy", ".npy", _npy_seed, _point_cloud),
            FileTarget("session", ".jsonl", _session_seed, _session), VmcTarget(), CliTarget()]

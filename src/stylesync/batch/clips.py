"""The clips of a batch and the key of each job.

INPUT is a folder (searched recursively), a glob pattern, a list file (``.list`` or ``.lst``: one clip path per
line, relative to the list's folder, ``#`` comments) or one clip file. A clip's source kind comes from its suffix:
``.bvh`` (BVH), ``.json`` (Azure Kinect body-tracking JSON), ``.txt`` (DeepMimic motion clip). A job is one clip
with one sensor seed; its key is a hash of the clip's content and the settings the run depends on, so a batch run
again with the same inputs and settings finds the jobs it has done, wherever the files were moved.
"""

from __future__ import annotations

import glob
import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from stylesync.errors import SourceError

KIND_BY_SUFFIX = {".bvh": "bvh", ".json": "k4a-json", ".txt": "deepmimic"}
LIST_SUFFIXES = (".list", ".lst")


@dataclass(frozen=True)
class BatchSettings:
    """What every job of a batch is run with (part of each job's key)."""

    seeds: tuple[int, ...] = (0,)
    sensor: str = "kinect"  # "kinect": the sensor model; "none": the frames as recorded
    duration_s: float | None = None  # cap on a run's simulated time [s] (None: the clip and its rest)
    export_bvh: bool = True
    export_mp4: bool = False
    lipm_time_sync: bool = True

    def as_dict(self) -> dict:
        return {"seeds": list(self.seeds), "sensor": self.sensor, "duration_s": self.duration_s,
                "export_bvh": self.export_bvh, "export_mp4": self.export_mp4, "lipm_time_sync": self.lipm_time_sync}


@dataclass(frozen=True)
class Job:
    """One clip with one seed."""

    clip: Path
    spec: str  # the source spec, e.g. "bvh:/path/to/clip.bvh"
    seed: int
    key: str  # hex digest of the clip's content, the seed and the settings
    name: str  # folder name of its outputs: the clip's stem, the seed and the key's head

    @property
    def group(self) -> str:
        """The folder the clip is in (the summary's rows)."""
        return self.clip.parent.name or "."


def find_clips(input_spec: str) -> list[Path]:
    """The clip files INPUT names, sorted; a clear error when there are none."""
    p = Path(input_spec).expanduser()
    if p.is_dir():
        found = [f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in KIND_BY_SUFFIX]
    elif p.is_file() and p.suffix.lower() in LIST_SUFFIXES:
        found = []
        for k, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            f = (p.parent / line).expanduser()
            if not f.is_file():
                raise SourceError(f"{p}, line {k}: no such clip file: {line}")
            found.append(f)
    elif p.is_file():
        found = [p]
    elif any(c in input_spec for c in "*?["):
        found = [Path(f) for f in glob.glob(str(p), recursive=True) if Path(f).is_file()]
    else:
        raise SourceError(f"{input_spec}: no such folder, list or clip file")
    clips = sorted({f.resolve() for f in found if f.suffix.lower() in KIND_BY_SUFFIX})
    if not clips:
        raise SourceError(f"{input_spec}: no clip files (.bvh, .json, .txt)")
    return clips


def jobs_for(clips: list[Path], settings: BatchSettings) -> list[Job]:
    """One job per clip and seed, keyed by the clip's content, the seed and the settings."""
    fixed = json.dumps({k: v for k, v in settings.as_dict().items() if k != "seeds"}, sort_keys=True)
    jobs = []
    for clip in clips:
        digest = hashlib.sha256(clip.read_bytes()).hexdigest()
        spec = f"{KIND_BY_SUFFIX[clip.suffix.lower()]}:{clip}"
        for seed in settings.seeds:
            key = hashlib.sha256(f"{digest}|{seed}|{fixed}".encode()).hexdigest()
            jobs.append(Job(clip, spec, seed, key, f"{clip.stem}-s{seed}-{key[:10]}"))
    return jobs

"""The clips of a batch and the key of each job.

INPUT is a folder (searched recursively), a glob pattern, a list file (``.list`` or ``.lst``: one clip path per
line, relative to the list's folder, ``#`` comments) or one clip file. A clip's source kind comes from its suffix:
``.bvh`` (BVH), ``.json`` (Azure Kinect body-tracking JSON), ``.txt`` (DeepMimic motion clip). A job is one clip
with one sensor seed; its key is a hash of the clip's content and the settings the run depends on, so a batch run
again with the same inputs and settings finds the jobs it has done, wherever the files were moved.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from stylesync.sources.clip_files import KIND_BY_SUFFIX, LIST_SUFFIXES, find_clips

__all__ = ["KIND_BY_SUFFIX", "LIST_SUFFIXES", "BatchSettings", "Job", "find_clips", "jobs_for"]


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

"""A user's clip files: a folder (searched recursively), a glob pattern, a list file (``.list`` or ``.lst``: one clip
path per line, relative to the list's folder, ``#`` comments) or one clip file; each clip's source kind from its
suffix (``.bvh`` BVH, ``.json`` Azure Kinect body-tracking JSON, ``.txt`` DeepMimic motion clip). `stylesync batch`
and `stylesync bench --suite dev --clips` find them so."""

from __future__ import annotations

import glob
from pathlib import Path

from stylesync.errors import SourceError

KIND_BY_SUFFIX = {".bvh": "bvh", ".json": "k4a-json", ".txt": "deepmimic"}
LIST_SUFFIXES = (".list", ".lst")


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

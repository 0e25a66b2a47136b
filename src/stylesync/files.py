"""Output files written whole or not at all."""

from __future__ import annotations

from pathlib import Path


def write_atomically(path: Path, data: str | bytes) -> None:
    """Write under a temporary name beside ``path``, then rename: a reader sees the old file or the whole new one
    (text as UTF-8)."""
    tmp = path.with_name(f".{path.name}.tmp")
    if isinstance(data, bytes):
        tmp.write_bytes(data)
    else:
        tmp.write_text(data, encoding="utf-8")
    tmp.replace(path)

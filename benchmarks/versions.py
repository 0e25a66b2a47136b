"""Helpers of the benchmarks that run several versions of stylesync in the same run: each version checked out in
a temporary git worktree, each measurement run in its own interpreter with that worktree's ``src/`` first on the
path (so both versions use their own code with this environment's libraries)."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


@contextlib.contextmanager
def checkouts(refs: dict[str, str]) -> Iterator[dict[str, Path]]:
    """Label -> git ref, checked out in temporary worktrees; yields label -> the worktree's ``src/``."""
    with tempfile.TemporaryDirectory() as tmp:
        trees = {label: Path(tmp) / f"tree{k}" for k, label in enumerate(refs)}
        try:
            for label, path in trees.items():
                subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(path), refs[label]],
                               check=True, capture_output=True)
            yield {label: path / "src" for label, path in trees.items()}
        finally:
            for path in trees.values():
                subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(path)], check=False,
                               capture_output=True)


def probe(src: Path, code: str, *args: str, timeout_s: float = 900.0) -> dict:
    """Run ``code`` (which prints one JSON object last) with ``src`` on the path; its object, or ``{"error": ...}``
    with the last line of its error output when it printed none."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, env=env,
                         timeout=timeout_s)
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith("{")]
    if not lines:
        return {"error": (out.stderr.strip().splitlines() or ["no output"])[-1][:200]}
    return json.loads(lines[-1])

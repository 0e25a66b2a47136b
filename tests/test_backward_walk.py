"""A backward walk's steps: his raised rear foot is not read as bearing weight while his way over the ground goes
backwards in his own frame (MotionConfig.rear_foot_stepping_way_mps; docs/decisions.md, "A backward walk")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig
from stylesync.metrics.summary import touchdowns

_WALK = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "05_01.bvh"


def _backward(tmp_path: Path) -> Path:
    """CMU 05_01 (a walk) with its frames in reverse order: the same person walking backwards, facing forwards."""
    lines = _WALK.read_text().splitlines()
    head = next(k for k, line in enumerate(lines) if line.strip().startswith("Frame Time")) + 1
    frames = [line for line in lines[head:] if line.strip()]
    out = tmp_path / "backward_05_01.bvh"
    out.write_text("\n".join(lines[:head] + frames[::-1]) + "\n")
    return out


def _steps(path: Path, stepping_way_mps: float | None) -> tuple[int, int, bool]:
    """His and the character's steps over the first 5 s (seed 0), and whether it fell."""
    motion = dataclasses.replace(MotionConfig(), rear_foot_stepping_way_mps=stepping_way_mps)
    result = suite_run(f"bvh:{path}", 0, motion, ControlConfig(), configure=lambda cfg: cfg.replace(duration_s=5.0))
    log = result.log
    return len(touchdowns(log.array("op_state"))), len(touchdowns(log.array("char_state"))), result.fell


@pytest.mark.skipif(not _WALK.is_file(), reason="../shared/mocap/cmu-dev (CMU 05_01) is not present")
def test_a_backward_walk_is_read_as_steps(tmp_path):
    """Walking backwards, his raised foot is behind his stance foot and his capture point behind its heel at every
    step, which read him as standing on both feet (a stealthy stride's rear foot on its toes): one step in 5 s, the
    character standing. His way goes backwards in his own frame: that foot steps. Measured: 8 steps of his and 8 of the
    character's, no fall; the forward clip gives him 9."""
    his, _, _ = _steps(_backward(tmp_path), None)
    assert his <= 2
    his, character, fell = _steps(_backward(tmp_path), MotionConfig().rear_foot_stepping_way_mps)
    assert his >= 6 and character >= 6 and not fell

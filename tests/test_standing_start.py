"""A recording started standing with the character's capture point near its toes: its feet are set down under it
(MotionConfig.standing_start_sole_share, motion/initial_state.standing_start_shift; docs/decisions.md, "A standing
start over the toes")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.metrics.bench import CONTROLLERS
from stylesync.model.sole import sole_corner_points, sole_points_xy_yaw
from stylesync.motion.initial_state import standing_start_shift
from stylesync.motion.stance_fsm import Stance
from stylesync.session import STANCE_CODE

_MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
_CLIP = _MOCAP / "cmu-dev" / "10_04.bvh"
_MID_STRIDE = _MOCAP / "cmu" / "02_01.bvh"
_G = 9.81


def _soles(share: float) -> list[list[tuple[float, float]]]:
    """Two flat soles facing +x, ankles at (0, ±0.1) [m], shrunk to ``share``."""
    corners = sole_corner_points(share)
    return [sole_points_xy_yaw(np.array([0.0, y, 0.0]), 0.0, corners) for y in (0.1, -0.1)]


def test_the_shift_puts_the_capture_point_on_the_soles():
    """A capture point 3 cm beyond the shrunk soles' front edge: the feet move 3 cm forwards, after which it lies on
    that edge; one within them, or a COM at rest over them, moves nothing."""
    soles = _soles(0.5)
    front = max(x for sole in soles for x, _ in sole)
    com = np.array([front + 0.03, 0.0, 0.85])
    shift = standing_start_shift(com, np.zeros(3), _G, soles)
    assert shift is not None and shift == pytest.approx([0.03, 0.0, 0.0], abs=1e-9)
    moved = [[(x + shift[0], y + shift[1]) for x, y in sole] for sole in soles]
    assert standing_start_shift(com, np.zeros(3), _G, moved) is None
    assert standing_start_shift(np.array([front - 0.01, 0.0, 0.85]), np.zeros(3), _G, soles) is None
    # ... the velocity counts: ξ = c + ċ / ω, a COM 1 cm inside moving forwards at 0.2 m/s is 5 cm beyond
    shift = standing_start_shift(np.array([front - 0.01, 0.0, 0.85]), np.array([0.2, 0.0, 0.0]), _G, soles)
    assert shift is not None and shift[0] == pytest.approx(0.2 / np.sqrt(_G / 0.85) - 0.01, abs=1e-9)


def _first_single_stances(share: float | None, at_rest: bool) -> tuple[float, float]:
    """CMU-dev 10_04 (a walk from standing, seed 0), its first 1.0 s: when he and the character first stand on one
    foot [s]."""
    control, motion = CONTROLLERS["stylesync"]
    motion = dataclasses.replace(motion, standing_start_sole_share=share, standing_start_at_rest=at_rest)
    result = suite_run(f"bvh:{_CLIP}", 0, motion, control, configure=lambda cfg: cfg.replace(duration_s=1.0))
    log = result.log
    t, ds = log.array("t"), STANCE_CODE[Stance.DS]
    his = float(t[np.argmax(log.array("op_state") != ds)])
    its = float(t[np.argmax(log.array("char_state") != ds)])
    return his, its


@pytest.mark.skipif(not _CLIP.is_file(), reason="../shared/mocap/cmu-dev (CMU-dev 10_04) is not present")
def test_a_standing_start_over_the_toes_waits_for_his_first_step():
    """Traced: he stands with his COM, as the pipeline reads it, 0.13 m ahead of his ankles (scaled); started so, the
    character's COM drifted over the front edge of its soles and it stepped on its own at 0.63 s, before his first
    lift-off (0.74 s), its feet out of his order after it. With its feet set 4 cm further under it, or started at rest
    (its start velocity of 0.20 m/s is the sensor's noise), it lifts a foot with him, and with both (the defaults)."""
    his, its = _first_single_stances(None, False)
    assert its < his - 0.05
    for share, at_rest in ((0.5, False), (None, True), (0.5, True)):
        his, its = _first_single_stances(share, at_rest)
        assert its >= his - 0.02, (share, at_rest)
    defaults = CONTROLLERS["stylesync"][1]
    assert (defaults.standing_start_sole_share, defaults.standing_start_at_rest) == (0.5, True)


def _start_speed(path: Path, at_rest: bool) -> float:
    """The character's root speed over the ground [m/s] at the first control tick of ``path`` (seed 0)."""
    control, motion = CONTROLLERS["stylesync"]
    motion = dataclasses.replace(motion, standing_start_at_rest=at_rest)
    speeds: list[float] = []
    suite_run(f"bvh:{path}", 0, motion, control, on_tick=lambda state, ref: speeds.append(
        float(np.hypot(*state.root_lin_vel_world[:2]))), configure=lambda cfg: cfg.replace(duration_s=0.01))
    return speeds[0]


@pytest.mark.skipif(not (_CLIP.is_file() and _MID_STRIDE.is_file()),
                    reason="../shared/mocap (CMU 02_01, CMU-dev 10_04) is not present")
def test_a_standing_start_is_at_rest_and_a_walk_started_mid_stride_moves():
    """A standing start's velocity over its first two frames is the sensor's noise (10_04, seed 0: 0.20 m/s): the
    character starts at rest (MotionConfig.standing_start_at_rest). A recording started mid-stride (CMU 02_01, 0.86
    m/s scaled) keeps its velocities."""
    assert _start_speed(_CLIP, False) > 0.1
    assert _start_speed(_CLIP, True) < 1e-6
    assert _start_speed(_MID_STRIDE, True) > 0.5

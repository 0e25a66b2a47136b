"""The pelvis target comes down as his swing goes, towards where the swing foot reaches its landing
(MotionConfig.swing_landing_within_reach), instead of within one control tick at a late contact."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator


def _late_contact_drops(within_reach: bool) -> tuple[np.ndarray, bool]:
    """The built-in walk (6 s, seed 0): the pelvis target's drop [m] on each control tick where a late contact begins
    to hold the reference, and whether the run fell. (Traced before the targets' pull onto his path.)"""
    cfg = SessionConfig(duration_s=6.0, operator=OperatorConfig(clip="walk"))
    cfg = cfg.replace(motion=dataclasses.replace(cfg.motion, swing_landing_within_reach=within_reach,
                                                 path_target_share=0.0))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    z: list[float] = []
    held: list[bool] = []

    def tick(state, ref):
        z.append(float(ref.pelvis_world[2]))
        held.append(session.reading.held)

    session.on_tick = tick
    result = session.run()
    heights, holding = np.array(z), np.array(held)
    onsets = np.where(holding[1:] & ~holding[:-1])[0]
    return heights[onsets] - heights[onsets + 1], result.fell


@pytest.mark.pelvis_joint
def test_a_late_contact_finds_the_pelvis_target_already_within_the_landing_feet_reach():
    before, fell_before = _late_contact_drops(False)
    after, fell_after = _late_contact_drops(True)
    assert not fell_before and not fell_after
    assert len(before) >= 3 and len(after) >= 3
    assert before.max() > 0.03, before  # lowered within one tick when the hold begins
    assert after.max() < 0.015, after

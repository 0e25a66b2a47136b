"""A step of the character's own that is due to land brings its pelvis down in the step's time, so that its foot
reaches the ground (WholeBodyConfig.landing_pelvis_gains; docs/decisions.md, "An own step's foot held above its
landing")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from conftest import TRACED_BEFORE_PRESS, suite_run

from stylesync.config import MotionConfig, WholeBodyConfig, follow_path
from stylesync.control.whole_body import recovery_landing_due
from stylesync.errors import ConfigError
from stylesync.model.character import ANKLE_HEIGHT_M, LINK_NAMES

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
CLIP = MOCAP / "cmu-dev" / "07_11.bvh"
_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
HOVER_M = 0.05  # an ankle this far above its height on the ground is in the air [m]


def _hover(gains: tuple[float, float] | None) -> tuple[int, int, bool]:
    """CMU-dev 07_11, sensor seed 5, with ``--follow-path``, to 3.6 s (1 s into the rest after the clip, where the
    trace of its fall began): the control ticks at which an own step's landing was due and its ankle was more than
    HOVER_M above the ground, all ticks with a landing due, and whether it fell."""
    hover, due = [0], [0]

    def on_tick(state, ref) -> None:
        for side, target in (ref.recovery_ankle_world or {}).items():
            if recovery_landing_due(target):
                due[0] += 1
                hover[0] += int(state.link_origin_world[_ANKLE[side], 2] > ANKLE_HEIGHT_M + HOVER_M)

    def configure(cfg):
        cfg = follow_path(cfg)
        wb = dataclasses.replace(cfg.control.whole_body, landing_pelvis_gains=gains)
        # (traced before the bound on the targets' lead, which keeps this run up by itself: off here)
        motion = dataclasses.replace(cfg.motion, reference_lead_max_m=None)
        return dataclasses.replace(cfg, duration_s=3.6, motion=motion,
                                   control=dataclasses.replace(cfg.control, whole_body=wb))

    result = suite_run(f"bvh:{CLIP}", 5, MotionConfig(), TRACED_BEFORE_PRESS, on_tick=on_tick, configure=configure)
    return hover[0], due[0], result.fell


@pytest.mark.pelvis_joint
@pytest.mark.skipif(not CLIP.exists(), reason="../shared/mocap/cmu-dev is not present")
def test_an_own_step_due_to_land_reaches_the_ground():
    hover, due, fell = _hover(None)
    # With the soft gains the hip stayed 0.05-0.13 m above its target, the leg straight, the foot 0.1-0.2 m up while
    # the body ran past its landing, and the character fell at 3.5 s (the foot more than HOVER_M up on 18 of the 55
    # ticks its landing was due since the rest's held pose keeps his leg's lengths, sources/held_pose.py)
    assert fell and due >= 20 and hover >= 0.3 * due, (hover, due, fell)
    hover, due, fell = _hover((100.0, 20.0))
    assert not fell and hover <= 0.1 * due, (hover, due, fell)


def test_the_landing_gains_are_two_non_negative_numbers():
    assert WholeBodyConfig(landing_pelvis_gains=[100, 20]).landing_pelvis_gains == (100.0, 20.0)
    for bad in ([100.0], 3.0, "ab", [-1.0, 20.0]):
        with pytest.raises(ConfigError):
            WholeBodyConfig(landing_pelvis_gains=bad)

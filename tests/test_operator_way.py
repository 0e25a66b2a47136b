"""The operator's way over the ground (motion/operator_way.py): a walk goes somewhere, a sway on the spot does not."""

from pathlib import Path

import numpy as np
import pytest

from stylesync.motion.operator_way import OperatorWay

DT_S = 1.0 / 60.0


def _run(way: OperatorWay, velocity, seconds: float) -> None:
    for k in range(int(round(seconds / DT_S))):
        way.update(velocity(k * DT_S))


def test_a_walk_goes_its_way_and_a_sway_on_the_spot_goes_nowhere():
    # A walk at 1 m/s along x whose COM sways ±0.3 m/s sideways at the step frequency (1 Hz).
    walk = OperatorWay(1.0, DT_S)
    _run(walk, lambda t: np.array([1.0, 0.3 * np.sin(2 * np.pi * t), 0.0]), 5.0)
    assert walk.goes(0.3)
    assert walk.direction_world() == pytest.approx(np.array([1.0, 0.0, 0.0]), abs=0.05)
    # A dancer swaying from foot to foot at 0.6 m/s peak: as fast, tick by tick, but he comes back.
    sway = OperatorWay(1.0, DT_S)
    _run(sway, lambda t: np.array([0.0, 0.6 * np.sin(2 * np.pi * 0.5 * t), 0.0]), 6.0)
    assert float(np.hypot(*sway.velocity_world)) < 0.2
    assert not sway.goes(0.3)
    assert sway.goes(None)  # without a speed, every double stance that moves between the feet is a gait's


def test_the_average_takes_its_time_constant_and_can_start_at_a_recordings_speed():
    way = OperatorWay(1.0, DT_S)
    _run(way, lambda t: np.array([1.0, 0.0]), 1.0)
    assert way.velocity_world[0] == pytest.approx(1.0 - np.exp(-1.0), abs=0.01)  # one time constant
    primed = OperatorWay(1.0, DT_S)
    primed.prime(np.array([1.2, 0.0, 0.0]))
    assert primed.goes(1.0) and primed.direction_world() == pytest.approx(np.array([1.0, 0.0, 0.0]))
    assert OperatorWay(1.0, DT_S).direction_world() is None  # at rest: no direction


ZOMBIE = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "deepmimic" / "humanoid3d_zombie_walk.txt"
# The four settings that follow the operator's path from rest (docs/decisions.md, "Keeping up at rest")
PATH_OPT_INS = {"double_stance_keeps_momentum_m": 0.1, "capture_bound_in_his_gait": False, "recovery_walk_on_m": 0.1,
                "path_feedback_share": 0.5}


@pytest.mark.skipif(not ZOMBIE.exists(), reason="../shared/mocap/deepmimic/humanoid3d_zombie_walk.txt is not available")
@pytest.mark.in_place
def test_the_zombie_walk_goes_his_way_when_its_own_steps_walk_on_only_along_it():
    """The zombie walk (seed 0, as the development suite runs it) with the path settings: its own steps walked on
    along the capture point's divergence, sideways too, and the character walked 3.6 m to the side of his path, its
    progress along it negative (-0.15). Walking on only along his way, and keeping a gait only while he goes somewhere,
    it goes 0.37 of his way (measured), with no fall either way. (Traced while a lift-off onto a sole the capture
    point has passed waited only the weight shift's time, ``liftoff_behind_waits`` off: with it, and these path
    settings alone, the walk goes 0.15 of his way; with all of ``--follow-path``'s it goes 0.92 either way.)"""
    import logging

    from conftest import TRACED_DIFFERENCED, suite_run

    from stylesync.config import MotionConfig
    from stylesync.metrics.summary import summarize

    logging.disable(logging.WARNING)
    try:
        spec = f"deepmimic:{ZOMBIE}"
        own = summarize(suite_run(spec, 0, MotionConfig(**PATH_OPT_INS, liftoff_behind_waits=False),
                                  TRACED_DIFFERENCED))
        his = summarize(suite_run(spec, 0, MotionConfig(**PATH_OPT_INS, recovery_walk_on_his_way=True,
                                                        gait_min_way_speed_mps=0.3, liftoff_behind_waits=False),
                                  TRACED_DIFFERENCED))
    finally:
        logging.disable(logging.NOTSET)
    assert not own["fell"] and not his["fell"]
    assert own["path_progress"] < 0.0
    assert his["path_progress"] > 0.25
    assert his["path_sideways_m"] < own["path_sideways_m"]


def test_his_way_along_it_and_not_across():
    """He goes his way while his present velocity is within the given angle of the average; not across it, not
    while the average is at rest, and not while he goes too slowly (OperatorWay.goes_along)."""
    import math

    way = OperatorWay(1.0, 0.01)
    way.prime(np.array([1.0, 0.0]))
    cos45 = math.cos(math.radians(45.0))
    assert way.goes_along(0.3, np.array([0.8, 0.3]), cos45)  # 20° off the way
    assert not way.goes_along(0.3, np.array([0.3, 0.8]), cos45)  # 69° off: a dance's swing
    assert not way.goes_along(0.3, np.array([0.1, 0.0]), cos45)  # too slow now
    way.prime(np.zeros(2))
    assert not way.goes_along(None, np.array([0.8, 0.3]), cos45)  # no way to go along

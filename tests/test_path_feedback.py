"""Following the operator over the ground by step placement (motion/path_feedback.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stylesync.config import ConfigError, MotionConfig
from stylesync.motion.path_feedback import PathReference, deadbeat_gain

OMEGA = 3.4  # the character's pendulum at a 0.85 m COM height [1/s]
STEP_S = 0.55  # a walking step: swing and double stance [s]


def _stance(xi: float, p: float, t_s: float) -> float:
    """The capture point after ``t_s`` on a foot at ``p`` (ξ̇ = ω (ξ - p)), along the walk [m]."""
    return p + (xi - p) * math.exp(OMEGA * t_s)


def test_the_reference_is_his_capture_point_scaled_about_both_starts():
    path = PathReference(share=0.5, max_m=1.0)
    # first tick: the character stands at (2, 1), he at (10, -3); both capture points over their pelvises
    d = path.update(np.array([2.0, 1.0, 0.9]), np.array([10.0, -3.0, 1.0]), np.array([2.0, 1.0, 0.0]),
                    np.array([10.0, -3.0, 0.0]), scale=0.8, omega_per_s=OMEGA)
    assert d == pytest.approx([0.0, 0.0])
    # he has gone 1 m along x; scaled, 0.8 m; the character has gone 0.5 m: 0.3 m behind
    d = path.update(np.array([9.0, 9.0, 0.9]), np.array([0.0, 0.0, 1.0]), np.array([2.5, 1.0, 0.0]),
                    np.array([11.0, -3.0, 0.0]), scale=0.8, omega_per_s=OMEGA)
    assert d == pytest.approx([-0.3, 0.0])  # the origins stay those of the first tick


@pytest.mark.parametrize("share", [0.0, 0.5, 1.0])
def test_a_step_removes_the_share_of_the_error(share):
    """A walker at steady pace (his landing 0.1 m behind his capture point, the pendulum's steady gait) and a
    character 0.3 m behind him: over one step with the landing moved by the feedback, the error becomes
    (1 - share) of what it was."""
    land = -0.1  # his landing relative to his capture point [m]
    xi_ref, xi_c = 1.0, 0.7
    path = PathReference(share=share, max_m=1.0)
    # both start at the origin
    path.update(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), scale=1.0, omega_per_s=OMEGA)
    delta = path.update(np.zeros(3), np.zeros(3), np.array([xi_c, 0.0, 0.0]), np.array([xi_ref, 0.0, 0.0]), 1.0, OMEGA)
    shift = path.landing_shift_xy(STEP_S)
    p_ref, p_c = xi_ref + land, xi_c + land + shift[0]
    after = _stance(xi_c, p_c, STEP_S) - _stance(xi_ref, p_ref, STEP_S)
    assert after == pytest.approx((1.0 - share) * delta[0], abs=1e-9)
    assert shift[1] == 0.0


def test_the_gain_is_the_pendulums_deadbeat_gain():
    assert deadbeat_gain(OMEGA, STEP_S) == pytest.approx(1.0 / (math.exp(OMEGA * STEP_S) - 1.0))
    assert deadbeat_gain(OMEGA, 0.0) > 1e5  # no step time: no finite landing removes the error


def test_the_landing_shift_is_bounded():
    path = PathReference(share=1.0, max_m=0.15)
    path.update(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), scale=1.0, omega_per_s=OMEGA)
    path.update(np.zeros(3), np.zeros(3), np.array([-3.0, 4.0, 0.0]), np.zeros(3), scale=1.0, omega_per_s=OMEGA)
    shift = path.landing_shift_xy(STEP_S)
    assert np.linalg.norm(shift) == pytest.approx(0.15)
    assert shift / np.linalg.norm(shift) == pytest.approx([-0.6, 0.8])  # along the error: behind, it lands behind


def test_off_by_default_and_validated():
    assert MotionConfig().path_feedback_share == 0.0
    assert not PathReference(MotionConfig().path_feedback_share, 0.2).enabled
    with pytest.raises(ConfigError, match="path_feedback_share"):
        MotionConfig(path_feedback_share=-0.1)


def test_follow_path_sets_the_opt_ins_and_the_start_at_speed():
    from stylesync.config import FOLLOW_PATH_MOTION, SessionConfig, follow_path

    cfg = follow_path(SessionConfig())
    assert cfg.operator.start_with_clip_velocity and not SessionConfig().operator.start_with_clip_velocity
    for name, value in FOLLOW_PATH_MOTION.items():
        assert getattr(cfg.motion, name) == value != getattr(SessionConfig().motion, name)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_built_in_walk_keeps_to_its_operators_path_longer_with_follow_path(seed):
    """Measured (3.5 s of the built-in walk): by default the UHC termination comes at 2.42-2.45 s, the character
    0.28-0.32 of the operator's way along; with follow_path at 2.79-3.00 s, 0.54-0.60 of it (2.99-3.05 s and
    0.61-0.62 before its own steps walked on only along his way and a gait needed him to go somewhere)."""
    import logging

    from stylesync.config import OperatorConfig, SessionConfig, follow_path
    from stylesync.metrics.summary import summarize
    from stylesync.session import Session
    from stylesync.sources.builtin_operator import builtin_operator

    logging.disable(logging.WARNING)
    try:
        out = {}
        for follow in (False, True):
            cfg = SessionConfig(duration_s=3.5, seed=seed, operator=OperatorConfig(clip="walk"))
            if follow:
                cfg = follow_path(cfg)
            source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, seed)
            out[follow] = summarize(Session(cfg, source).run())
    finally:
        logging.disable(logging.NOTSET)
    assert not out[False]["fell"] and not out[True]["fell"]
    assert out[False]["uhc_fall_time_s"] < 2.6
    assert out[True]["uhc_fall_time_s"] is None or out[True]["uhc_fall_time_s"] > 2.7
    assert out[True]["path_progress"] > 1.6 * out[False]["path_progress"]

"""Both soles loaded where he stands still (WholeBodyConfig.standing_sole_min_load_share).

A person standing with his weight over one foot leaves the character's other sole all but unloaded: its contact force
crossed the pressing threshold up and down from one control tick to the next, the sole left the QP's contacts and came
back, slid, and the character stepped to put it back, again and again. The bound ends where the character's own
weight shift for a step to where he stands begins (it would hold that shift back)."""

import dataclasses

import numpy as np
import pytest

from stylesync.config import SessionConfig
from stylesync.control.solver import DaqpSolver
from stylesync.experiments.scripted_operator import pose_frame, standing_ankles
from stylesync.metrics.summary import summarize
from stylesync.model.character import N_DOFS
from stylesync.motion.pose_optimization import CHARACTER_STANDS_MPS
from stylesync.motion.stance_fsm import Stance
from stylesync.processing.interpolation import smooth_step
from stylesync.session import Session
from stylesync.sources.builtin_operator import sensed
from stylesync.sources.human_model import HumanModel

SHIFT_M = 0.11  # his pelvis moved this far to the right: 2 cm beyond his right ankle (the hip's half width 0.091 m)
BEYOND_M = 0.12  # ... and so far that the character's COM, following his, leaves its sole: it steps out and back [m]


def _weight_on_one_foot(share: float, seed: int = 0, on_tick=None, shift_m: float = SHIFT_M) -> dict:
    """He stands, moves his pelvis ``shift_m`` to the right between 1 and 2 s, over his right foot, and stands so
    until 8 s."""
    cfg = SessionConfig(duration_s=8.0, seed=seed)
    wb = dataclasses.replace(cfg.control.whole_body, standing_sole_min_load_share=share)
    cfg = cfg.replace(control=dataclasses.replace(cfg.control, whole_body=wb))
    human = HumanModel(cfg.operator.height_m, cfg.operator.mass_kg)
    stand, hip_h = standing_ankles(human), human.hip_height_m - 0.02

    def frame_at(t_s: float):
        return pose_frame(human, t_s, np.array([0.0, -shift_m * smooth_step(t_s - 1.0), hip_h]), stand)

    session = Session(cfg, sensed(frame_at, cfg.operator, cfg.clocks, cfg.duration_s + 1.0, seed, "weight-shift"))
    if on_tick is not None:
        session.on_tick = lambda state, ref: on_tick(session, state, ref)
    result = session.run()
    return summarize(result)


def test_a_sole_his_weight_leaves_stays_loaded_and_the_character_stands():
    assert SessionConfig().control.whole_body.standing_sole_min_load_share == 0.1  # the default
    loaded = _weight_on_one_foot(0.1)
    off = _weight_on_one_foot(0.0)
    assert not loaded["fell"] and not off["fell"]
    assert loaded["operator_steps"] == off["operator_steps"] == 0
    assert off["character_steps"] >= 4  # without the bound: the unloaded sole slides, and is stepped back, again
    assert loaded["character_steps"] == 0


def test_the_planned_normal_forces_keep_the_bound_while_he_stands_still():
    """His COM beyond his right ankle so far that the character's steps out and back: the bound holds wherever
    both soles stand while he stands still, but not in the weight shift for a step to where he stands, nor while
    the character's body travels."""
    seen = {"bound": 0, "free": 0, "rest_shift": 0, "travels": 0}

    def check(session, state, ref):
        if session.motion._rest_stance is not None:  # a step to where he stands: its weight shift is not held back
            seen["rest_shift"] += 1
            assert not ref.both_stand_still
        if float(np.hypot(*session.mass.com_velocity(state)[:2])) >= CHARACTER_STANDS_MPS:  # (a body still braking)
            seen["travels"] += 1
            assert not ref.both_stand_still
        c = session.controller
        if c._last_qp is None or state.time_s < 3.0:
            return
        contacts, _, problem = c._last_qp
        x = DaqpSolver().solve(problem).x
        start = N_DOFS
        for sole in contacts:
            normal = float(sole.normal_row @ x[start:start + sole.n_forces])
            start += sole.n_forces
            pressing = state.feet_pressing()
            if ref.both_stand_still and ref.character_stance is Stance.DS and all(pressing.values()):
                assert len(contacts) == 2  # both soles on the ground stay contacts, whatever their stance weight
            if len(contacts) == 2 and ref.both_stand_still:
                seen["bound"] += 1
                assert sole.min_normal_force_n == pytest.approx(
                    0.1 * sole.body_weight_n * min(1.0, sole.stance_weight / 0.1))
                assert normal >= sole.min_normal_force_n - 1e-6
            else:
                seen["free"] += 1
                assert sole.min_normal_force_n == 0.0

    _weight_on_one_foot(0.1, on_tick=check, shift_m=BEYOND_M)
    assert seen["bound"] > 100  # ticks with both soles under him while he stands still
    assert seen["rest_shift"] > 0 and seen["travels"] > 0

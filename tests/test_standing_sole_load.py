"""Both soles loaded where he stands still (WholeBodyConfig.standing_sole_min_load_share, opt-in).

A person standing with his weight over one foot leaves the character's other sole all but unloaded: its contact force
crossed the pressing threshold up and down from one control tick to the next, the sole left the QP's contacts and came
back, slid, and the character stepped to put it back, again and again."""

import dataclasses

import numpy as np
import pytest

from stylesync.config import SessionConfig
from stylesync.control.solver import DaqpSolver
from stylesync.experiments.scripted_operator import pose_frame, standing_ankles
from stylesync.metrics.summary import summarize
from stylesync.model.character import N_DOFS
from stylesync.processing.interpolation import smooth_step
from stylesync.session import Session
from stylesync.sources.builtin_operator import sensed
from stylesync.sources.human_model import HumanModel

SHIFT_M = 0.12  # his pelvis moved this far over his right foot (beyond the hip's half width) [m]


def _weight_on_one_foot(share: float, seed: int = 0, on_tick=None) -> dict:
    """He stands, moves his pelvis over his right foot between 1 and 2 s and stands so until 8 s."""
    cfg = SessionConfig(duration_s=8.0, seed=seed)
    wb = dataclasses.replace(cfg.control.whole_body, standing_sole_min_load_share=share)
    cfg = cfg.replace(control=dataclasses.replace(cfg.control, whole_body=wb))
    human = HumanModel(cfg.operator.height_m, cfg.operator.mass_kg)
    stand, hip_h = standing_ankles(human), human.hip_height_m - 0.02

    def frame_at(t_s: float):
        return pose_frame(human, t_s, np.array([0.0, -SHIFT_M * smooth_step(t_s - 1.0), hip_h]), stand)

    session = Session(cfg, sensed(frame_at, cfg.operator, cfg.clocks, cfg.duration_s + 1.0, seed, "weight-shift"))
    if on_tick is not None:
        session.on_tick = lambda state, ref: on_tick(session, state, ref)
    result = session.run()
    return summarize(result)


def test_a_sole_his_weight_leaves_stays_loaded_and_the_character_stands():
    assert SessionConfig().control.whole_body.standing_sole_min_load_share == 0.0  # opt-in
    loaded = _weight_on_one_foot(0.1)
    off = _weight_on_one_foot(0.0)
    assert not loaded["fell"] and not off["fell"]
    assert loaded["operator_steps"] == off["operator_steps"] == 0
    assert off["character_steps"] >= 5  # without the bound: the unloaded sole slides, and is stepped back, again
    assert loaded["character_steps"] <= 1


def test_the_planned_normal_forces_keep_the_bound_while_he_stands_still():
    seen = {"bound": 0, "free": 0}

    def check(session, state, ref):
        c = session.controller
        if c._last_qp is None or state.time_s < 3.0:
            return
        contacts, _, problem = c._last_qp
        x = DaqpSolver().solve(problem).x
        start = N_DOFS
        for sole in contacts:
            normal = float(sole.normal_row @ x[start:start + sole.n_forces])
            start += sole.n_forces
            if len(contacts) == 2 and ref.he_stands_still:
                seen["bound"] += 1
                assert sole.min_normal_force_n == pytest.approx(
                    0.1 * sole.body_weight_n * min(1.0, sole.stance_weight / 0.1))
                assert normal >= sole.min_normal_force_n - 1e-6
            else:
                seen["free"] += 1
                assert sole.min_normal_force_n == 0.0

    _weight_on_one_foot(0.1, on_tick=check)
    assert seen["bound"] > 100  # ticks with both soles under him while he stands still

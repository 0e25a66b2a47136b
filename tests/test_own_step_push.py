"""The bound on the push of a character's own step (control/own_step_push.py): the pendulum's force with the centre
of pressure at the sole's rear edge, as one inequality the QP's solution keeps, only along the divergence; and the
traced chain of own steps that it stops."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig, WholeBodyConfig
from stylesync.control.contacts import MOMENTUM_ACCEL_ALLOWANCE_MPS2, SoleContact
from stylesync.control.formulation import WholeBodyFormulation
from stylesync.control.own_step_push import own_step_push_bound
from stylesync.control.solver import DaqpSolver
from stylesync.control.tasks import CentroidalMomentumTask, JointPostureTask
from stylesync.control.whole_body import _TORQUE_LIMIT_FLAT
from stylesync.model.character import N_DOFS, ROOT_DOFS

G = 9.8


@pytest.fixture(scope="module")
def on_left_foot(standing):
    """The character standing (conftest.standing), its model's state given a forward and leftward COM velocity; the
    left sole."""
    backend, model = standing
    state = backend.read_state(0.5)
    state.root_lin_vel_world = np.array([0.8, 0.3, 0.0])
    model.update(state)
    contact = SoleContact("left", 0.9, model.total_mass_kg * G)
    contact.update(model)
    return model, contact


def test_the_bound_is_the_pendulums_force_at_the_soles_rear_edge(on_left_foot):
    model, contact = on_left_foot
    m = model.total_mass_kg
    bound = own_step_push_bound(model, contact.corners_world, m, G)
    centre = contact.corners_world.mean(axis=0)
    com, vel = model.com_world, model.com_vel_world
    omega = np.sqrt(G / (com[2] - centre[2]))
    d = (com + vel / omega - centre)[:2]
    u = d / np.linalg.norm(d)
    np.testing.assert_allclose(bound.row, u[0] * model.centroidal_map[0] + u[1] * model.centroidal_map[1])
    rear = (contact.corners_world[:, :2] @ u).min()
    f_max = m * (omega**2 * (com[:2] @ u - rear) + MOMENTUM_ACCEL_ALLOWANCE_MPS2)
    assert bound.upper == pytest.approx(f_max - u @ model.centroidal_map_dot_v[:2])
    assert bound.lower < -1e9  # braking is not bounded


def _horizontal_force_along(model, qdd, u):
    return float(u @ (model.centroidal_map[:2] @ qdd + model.centroidal_map_dot_v[:2]))


def test_a_qp_with_the_bound_does_not_push_past_it(on_left_foot):
    """The momentum task asks for a push along the divergence twice the bound: without the bound the ground gives
    more than the pendulum at the rear edge allows; with it, no more. A brake the other way is the same either way."""
    model, contact = on_left_foot
    m = model.total_mass_kg
    bound = own_step_push_bound(model, contact.corners_world, m, G)
    centre = contact.corners_world.mean(axis=0)
    omega = np.sqrt(G / (model.com_world[2] - centre[2]))
    d = (model.com_world + model.com_vel_world / omega - centre)[:2]
    u = d / np.linalg.norm(d)
    f_max = bound.upper + float(u @ model.centroidal_map_dot_v[:2])
    along = {}
    for sign in (1.0, -1.0):
        for bounded in (False, True):
            formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, (), 10.0, 0.05)
            posture = formulation.add_task(JointPostureTask(1.0, 0.05))
            posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
            momentum = formulation.add_task(CentroidalMomentumTask(100.0, 1.0))
            push = sign * 2.0 * f_max
            momentum.force_n = np.array([push * u[0], push * u[1], m * G])
            problem = formulation.build(model, [contact], [bound] if bounded else [])
            result = DaqpSolver().solve(problem)
            assert result.solved
            along[sign, bounded] = _horizontal_force_along(model, result.x[:N_DOFS], u)
    assert along[1.0, False] > f_max + 10.0
    assert along[1.0, True] <= f_max + 1e-6
    assert along[-1.0, True] == pytest.approx(along[-1.0, False], abs=1e-6)
    assert along[-1.0, True] < 0.0


MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
needs_cmu_dev = pytest.mark.skipif(not (MOCAP / "cmu-dev").is_dir(),
                                   reason="../shared/mocap/cmu-dev (Poser/DAZ CMU clips) is not present")


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@needs_cmu_dev
@pytest.mark.parametrize("push_bound", ["off", "he_stands"])
@pytest.mark.in_place
def test_a_chain_of_own_steps_in_the_rest_is_not_pushed_on(push_bound):
    """CMU-dev 08_08, seed 11 (traced): after the clip's end the operator stands; without the bound the character's
    own steps push its COM from 1.1 to 3 m/s (horizontally) and it falls 1.4 s into the rest. With the bound in the
    steps taken while he stands (the default), it comes to rest. Traced with the pelvis height's regulator alone
    (WholeBodyConfig.pelvis_rate_share 0), and while a lift-off onto a sole the capture point has passed waited only
    the weight shift's time (MotionConfig.liftoff_behind_waits off: with it, the run without the bound stands too),
    and before the pelvis target came down as his swing went (MotionConfig.swing_landing_within_reach off)."""
    speeds = []
    control = ControlConfig(whole_body=WholeBodyConfig(own_step_push_bound=push_bound, pelvis_rate_share=0.0,
                                                       recovery_foot_target_rate="differenced"))

    def watch(session):
        return lambda state, ref: speeds.append(float(np.hypot(*session.mass.com_velocity(state)[:2])))

    result = suite_run(f"bvh:{MOCAP / 'cmu-dev' / '08_08.bvh'}", 11,
                       MotionConfig(liftoff_behind_waits=False, swing_landing_within_reach=False), control, watch=watch)
    if push_bound == "off":
        assert result.fell and max(speeds) > 2.5
    else:
        assert not result.fell and max(speeds) < 2.0 and speeds[-1] < 0.3

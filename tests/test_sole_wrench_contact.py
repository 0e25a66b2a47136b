"""The soles' wrench cone (control/sole_wrench_contact.py): its faces bound exactly the wrenches the corner pyramids
can give, its regularisation is the corner forces' least-norm one, and a QP with it obeys the equations of motion,
the contacts and the cone."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls

from stylesync.control.contacts import REGULARISATION, SOLE_CORNERS_IN_SOLE, SoleContact, pyramid_edges
from stylesync.control.formulation import WholeBodyFormulation
from stylesync.control.sole_wrench_contact import (
    WRENCH_SIZE,
    SoleWrenchContact,
    contact_wrench_cone,
    corner_wrench_generators,
)
from stylesync.control.solver import DaqpSolver
from stylesync.control.tasks import JointPostureTask
from stylesync.control.whole_body import _TORQUE_LIMIT_FLAT
from stylesync.model.character import N_DOFS, ROOT_DOFS


def test_the_cone_holds_exactly_what_the_corner_pyramids_give():
    """A wrench satisfies U w <= 0 if and only if non-negative corner forces give it (non-negative least squares
    with no residual), over random wrenches in, near and out of the cone; every face holds 5 independent
    generators (a facet, not a redundant row)."""
    g = corner_wrench_generators(pyramid_edges(0.9), SOLE_CORNERS_IN_SOLE)
    u = contact_wrench_cone(g)
    assert u.shape == (32, WRENCH_SIZE)
    assert np.max(u @ g) < 1e-9
    for row in u:
        on_face = np.abs(row @ g) < 1e-9
        assert np.linalg.matrix_rank(g[:, on_face]) == 5
    rng = np.random.default_rng(0)
    inside_count = 0
    for _ in range(2000):
        noise = rng.uniform(0.0, 3.0) * rng.normal(size=6) * [1.0, 1.0, 1.0, 0.1, 0.1, 0.1]
        w = g @ rng.uniform(0.0, 1.0, g.shape[1]) + noise
        inside = float(np.max(u @ w)) <= 1e-9
        _, residual = nnls(g, w)
        assert inside == (residual < 1e-7)
        inside_count += inside
    assert 200 < inside_count < 1800  # both kinds were drawn


def test_the_regularisation_is_the_least_norm_corner_forces():
    """ε wᵀ (G Gᵀ)⁻¹ w equals ε |λ|² for the least-norm corner forces λ of w: here a standing sole's wrench, whose
    least-norm λ are all positive (so the pyramid contact's regularisation of that wrench is the same)."""
    g = corner_wrench_generators(pyramid_edges(0.9), SOLE_CORNERS_IN_SOLE)
    w = np.array([5.0, -3.0, 220.0, 2.0, -4.0, 0.3])
    lam = np.linalg.pinv(g) @ w
    assert lam.min() > 0.0
    contact = SoleWrenchContact("left", 0.9, 45.0 * 9.8)
    h = np.zeros((8, 8))
    contact._metric_world = contact._metric_in_sole  # the sole's axes are the world's
    contact.add_regularisation(h, 2)
    assert 0.5 * w @ h[2:, 2:] @ w == pytest.approx(0.5 * REGULARISATION * lam @ lam, rel=1e-9)
    assert np.count_nonzero(h[:2]) == 0 and np.count_nonzero(h[:, :2]) == 0


def test_a_qp_with_wrench_contacts_obeys_the_dynamics_the_contacts_and_the_cone(turned_model):
    """A character turned by 0.6 rad, sinking onto its feet: the solution's torques and wrenches satisfy the
    equations of motion, the soles do not accelerate, each wrench is inside its sole's cone turned with the sole,
    and the soles push as hard as the corner pyramids' QP of the same state has them push."""
    model = turned_model
    formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, (), 10.0, 0.05)
    posture = formulation.add_task(JointPostureTask(10.0, 0.05))
    posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
    contacts = [SoleWrenchContact(s, 0.9, 45.0 * 9.8) for s in ("left", "right")]
    problem = formulation.build(model, contacts)
    assert problem.H.shape == (N_DOFS + 2 * WRENCH_SIZE,) * 2
    result = DaqpSolver().solve(problem)
    assert result.solved
    qdd, wrenches = result.x[:N_DOFS], result.x[N_DOFS:].reshape(2, WRENCH_SIZE)
    gen = np.hstack([c.generator for c in contacts])
    tau = formulation.torques(model, problem, result.x)
    residual = model.mass_matrix @ qdd + model.bias_forces - gen @ result.x[N_DOFS:]
    np.testing.assert_allclose(residual[:ROOT_DOFS], 0.0, atol=1e-6)
    np.testing.assert_allclose(residual[ROOT_DOFS:], tau, atol=1e-6)
    cone = contact_wrench_cone(corner_wrench_generators(pyramid_edges(0.9), SOLE_CORNERS_IN_SOLE))
    for c, w in zip(contacts, wrenches, strict=True):
        jac, acc = c.constraint_rows(10.0)
        np.testing.assert_allclose(jac @ qdd, acc, atol=1e-6)
        r = model.frame_placement(model.frame_id(c.frame)).rotation
        w_sole = np.concatenate([r.T @ w[:3], r.T @ w[3:]])
        assert np.max(cone @ w_sole) <= 1e-6
    pyramids = [SoleContact(s, 0.9, 45.0 * 9.8) for s in ("left", "right")]
    lam = DaqpSolver().solve(formulation.build(model, pyramids)).x[N_DOFS:]
    normal = sum(float(c.normal_row @ lam[16 * i:16 * (i + 1)]) for i, c in enumerate(pyramids))
    assert wrenches[:, 2].sum() == pytest.approx(normal, rel=0.01)
    assert normal > model.total_mass_kg * 9.8  # it brakes its fall


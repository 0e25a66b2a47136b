"""The whole-body controller's parts: sole contacts (generator against finite differences), the formulation (its
solutions obey the equations of motion, the contacts and the limits), the solver (warm start = cold start), tasks
added by one line (a hand-position task switched on by a flag)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig, OperatorConfig, SessionConfig, WholeBodyConfig
from stylesync.control.contacts import FORCES_PER_SOLE, SoleContact
from stylesync.control.formulation import INFINITY, WholeBodyFormulation, hinge_limits
from stylesync.control.solver import DaqpSolver
from stylesync.control.tasks import JointPostureTask, Task, TaskRows
from stylesync.control.whole_body import _TORQUE_LIMIT_FLAT, HAND_REACH_SHARE
from stylesync.model.character import N_DOFS, ROOT_DOFS
from stylesync.model.character_model import CharacterModel
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"


def test_contact_generator_is_the_corner_forces_power(standing):
    """(Bᵀ v)_{c,e} = β_e · v_c: the generator maps each unit pyramid force to the generalised force whose power
    at velocity v is that of the force at its corner (corner velocities by finite differences on the manifold)."""
    _, model = standing
    contact = SoleContact("left", 0.9, 45.0 * 9.8)
    contact.update(model)
    rng = np.random.default_rng(0)
    v = rng.normal(size=N_DOFS)
    corners0 = contact.corners_world.copy()
    q0 = model.q.copy()
    eps = 1e-7
    v_pin = np.zeros(N_DOFS)
    v_pin[model._perm] = v  # the character's layout -> Pinocchio's
    model.update_qv(pin.integrate(model.model, q0, v_pin * eps), np.zeros(N_DOFS))
    moved = SoleContact("left", 0.9, 45.0 * 9.8)
    moved.update(model)
    corner_vel = (moved.corners_world - corners0) / eps  # (4, 3)
    expected = np.array([e @ corner_vel[c] for c in range(4) for e in contact.edges])
    np.testing.assert_allclose(contact.generator.T @ v, expected, atol=1e-5)
    model.update_qv(q0, np.zeros(N_DOFS))


def test_a_contact_is_evaluated_once_per_model_update(standing):
    """The controller reads a sole's corners before the QP is built, and the formulation updates its contacts: the
    second update of the same state is skipped; the next state's is done."""
    _, model = standing
    q0 = model.q.copy()
    model.update_qv(q0, np.zeros(N_DOFS))
    contact = SoleContact("left", 0.9, 45.0 * 9.8)
    contact.update(model)
    generator = contact.generator
    contact.update(model)
    assert contact.generator is generator
    model.update_qv(q0, np.zeros(N_DOFS))
    contact.update(model)
    assert contact.generator is not generator
    np.testing.assert_allclose(contact.generator, generator, atol=1e-9)  # the same state, evaluated again


def _standing_problem(model):
    formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, (), 10.0, 0.05)
    posture = formulation.add_task(JointPostureTask(10.0, 0.05))
    posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
    contacts = [SoleContact(s, 0.9, 45.0 * 9.8) for s in ("left", "right")]
    return formulation, contacts


def test_solution_obeys_the_equations_of_motion_contacts_and_limits(standing):
    _, model = standing
    formulation, contacts = _standing_problem(model)
    problem = formulation.build(model, contacts)
    result = DaqpSolver().solve(problem)
    assert result.solved
    qdd, lam = result.x[:N_DOFS], result.x[N_DOFS:]
    assert lam.shape == (2 * FORCES_PER_SOLE,)
    assert lam.min() >= -1e-9  # inside the friction pyramids
    gen = np.hstack([c.generator for c in contacts])
    tau = formulation.torques(model, problem, result.x)
    residual = model.mass_matrix @ qdd + model.bias_forces - gen @ lam
    np.testing.assert_allclose(residual[:ROOT_DOFS], 0.0, atol=1e-6)  # the root is not actuated
    np.testing.assert_allclose(residual[ROOT_DOFS:], tau, atol=1e-6)  # the joints' torques
    assert np.all(np.abs(tau) <= _TORQUE_LIMIT_FLAT + 1e-6)
    for c in contacts:  # the soles do not accelerate (beyond the damping of their residual velocity)
        jac, acc = c.constraint_rows(10.0)
        np.testing.assert_allclose(jac @ qdd, acc, atol=1e-6)
    normal = sum(float(c.normal_row @ lam[16 * i:16 * (i + 1)]) for i, c in enumerate(contacts))
    assert normal == pytest.approx(model.total_mass_kg * 9.8, rel=0.05)  # standing: the feet carry the body


def test_hinge_limits_bound_the_accelerations_that_keep_them_over_the_horizon(standing):
    """Each hinge's row is q̈ alone, bounded so that q + q̇ T + ½ q̈ T² stays within its limits (never tighter than 0)."""
    _, model = standing
    limits = hinge_limits(model.joint_limits_rad)
    assert len(limits) == 4  # knees and elbows
    t = 0.05
    formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, limits, 10.0, t)
    posture = formulation.add_task(JointPostureTask(10.0, 0.05))
    posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
    problem = formulation.build(model, [SoleContact("left", 0.9, 45.0 * 9.8)])
    c_rows, lo, hi = problem.C[-len(limits):], problem.l[-len(limits):], problem.u[-len(limits):]
    for k, lim in enumerate(limits):
        assert np.flatnonzero(c_rows[k]).tolist() == [lim.dof] and c_rows[k, lim.dof] == 1.0
        q, qd = model.joint_position(lim.dof), model.v[lim.dof]
        assert lo[k] == pytest.approx(min(2.0 * (lim.lower_rad - q - qd * t) / t ** 2, 0.0))
        assert hi[k] == pytest.approx(max(2.0 * (lim.upper_rad - q - qd * t) / t ** 2, 0.0))
        assert lo[k] <= 0.0 <= hi[k]
    np.testing.assert_array_equal(problem.b, problem.lower[:problem.n_eq])
    np.testing.assert_array_equal(problem.upper[:problem.n_eq], problem.lower[:problem.n_eq])  # equalities


def test_opening_a_problems_limits_opens_its_torque_and_hinge_rows_only(standing):
    """What gives way when a QP has no feasible point: the torque rows and the hinges' rows are bounded by
    ±INFINITY, every other bound (the root's equations, the soles' rows, their forces) stays, and the problem opened
    is a copy. Its solution still obeys the equations of motion and the contacts."""
    _, model = standing
    limits = hinge_limits(model.joint_limits_rad)
    formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, limits, 10.0, 0.05)
    posture = formulation.add_task(JointPostureTask(10.0, 0.05))
    posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
    contacts = [SoleContact(s, 0.9, 45.0 * 9.8) for s in ("left", "right")]
    problem = formulation.build(model, contacts)
    lower, upper = problem.lower.copy(), problem.upper.copy()
    opened = formulation.with_limits_opened(problem)
    n_eq, n_tau, n_rows = problem.n_eq, N_DOFS - ROOT_DOFS, len(problem.lower)
    changed = np.flatnonzero((opened.lower != problem.lower) | (opened.upper != problem.upper))
    assert changed.tolist() == list(range(n_eq, n_eq + n_tau)) + list(range(n_rows - len(limits), n_rows))
    assert np.all(opened.lower[changed] <= -INFINITY) and np.all(opened.upper[changed] >= INFINITY)
    np.testing.assert_array_equal(problem.lower, lower)  # the problem itself is left as it was
    np.testing.assert_array_equal(problem.upper, upper)
    result = DaqpSolver().solve(opened)
    assert result.solved
    qdd, lam = result.x[:N_DOFS], result.x[N_DOFS:]
    residual = model.mass_matrix @ qdd + model.bias_forces - np.hstack([c.generator for c in contacts]) @ lam
    np.testing.assert_allclose(residual[:ROOT_DOFS], 0.0, atol=1e-6)
    for c in contacts:
        jac, acc = c.constraint_rows(10.0)
        np.testing.assert_allclose(jac @ qdd, acc, atol=1e-6)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_11.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_11.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_qp_with_no_feasible_point_does_not_throw_the_limbs():
    """CMU-dev 07_11 (a walk, seed 2): at 1.35 s a recovery step begins from a double stance with the feet 0.64 m
    apart; the QP has no feasible point for four ticks (DAQP exit -1), and its last iterate, applied as torques,
    threw the arms at 38 m/s: "the motion diverged" at 1.37 s with the pelvis at 0.77 m (measured). Solved again
    with the torque and hinge limits opened, the walk completes."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_11.bvh'}"

    def run(relax: bool):
        sessions = []

        def watch(session):
            sessions.append(session)
            return None

        control = ControlConfig(whole_body=WholeBodyConfig(relax_limits_when_infeasible=relax,
                                                           joint_speed_limit_rad_s=None,
                                                           recovery_foot_target_rate="differenced"))
        # traced before the joints' no-load speed, the crossover steps, the earlier touchdown of a recovery step's
        # foot, the swing aimed at the operator's last landing and the pelvis target that comes down as his swing goes
        motion = MotionConfig(recovery_cross_clear_m=None, recovery_touchdown_share=1.0, recovery_landing_gap_m=None,
                              swing_landing="his_foot_now", swing_landing_within_reach=False)
        result = suite_run(spec, 2, motion, control, watch=watch)
        return result, sessions[0].controller.relaxed_solves

    (relaxed, count), (last_iterate, _) = run(True), run(False)
    assert not relaxed.fell and count > 0
    assert last_iterate.fell and "diverged" in last_iterate.fall_reason and last_iterate.fall_time_s < 1.5


def test_warm_start_reaches_the_cold_solution(standing):
    _, model = standing
    formulation, contacts = _standing_problem(model)
    problem = formulation.build(model, contacts)
    solver = DaqpSolver()
    cold = solver.solve(problem)
    formulation.task("posture").desired_accel = np.full(N_DOFS - ROOT_DOFS, 0.5)  # type: ignore[attr-defined]
    problem2 = formulation.build(model, contacts)
    warm = solver.solve(problem2)
    fresh = DaqpSolver().solve(problem2)
    assert cold.solved and warm.solved and fresh.solved
    np.testing.assert_allclose(warm.x, fresh.x, atol=1e-6)


def test_a_task_is_a_class_and_one_line(standing):
    """A task defined here, added with one line, changes the solution toward what it asks."""
    _, model = standing

    class LeanChest(Task):
        name = "lean_chest"

        def rows(self, m: CharacterModel) -> TaskRows:
            j = np.zeros((1, N_DOFS))
            j[0, ROOT_DOFS + 2] = 1.0  # the chest's third DOF
            return TaskRows(j, np.array([3.0]), np.array([100.0]))

    formulation, contacts = _standing_problem(model)
    before = DaqpSolver().solve(formulation.build(model, contacts)).x[ROOT_DOFS + 2]
    formulation.add_task(LeanChest())
    after = DaqpSolver().solve(formulation.build(model, contacts)).x[ROOT_DOFS + 2]
    assert abs(after - 3.0) < abs(before - 3.0)
    assert after == pytest.approx(3.0, abs=0.5)


def _hand_error(hand_tasks: bool) -> tuple[float, bool]:
    """Mean distance of the left wrist to the hand target (the operator's wrist around his pelvis, scaled, within
    the arm's reach: what the hand task asks), over a punch."""
    cfg = SessionConfig(duration_s=2.5, operator=OperatorConfig(clip="punch"),
                        control=ControlConfig(whole_body=WholeBodyConfig(hand_tasks=hand_tasks)))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    model = session.model
    reach = HAND_REACH_SHARE * (model.rest_distance("left_shoulder", "left_elbow")
                                + model.rest_distance("left_elbow", "left_wrist"))
    errors: list[float] = []

    def tick(state, ref):
        if ref.hand_world is not None and state.time_s > 1.0:
            shoulder = model.frame_position(model.frame_id("left_shoulder"))
            offset = ref.hand_world["left"] - shoulder
            target = shoulder + offset * min(1.0, reach / float(np.linalg.norm(offset)))
            errors.append(float(np.linalg.norm(model.frame_position(model.frame_id("left_wrist")) - target)))

    session.on_tick = tick
    result = session.run()
    return float(np.mean(errors)), result.fell


def test_hand_tasks_bring_the_hands_to_the_operators():
    with_tasks, fell = _hand_error(True)
    without, _ = _hand_error(False)
    assert not fell
    assert with_tasks < 0.7 * without, (with_tasks, without)


def _jump_run(share: float) -> dict:
    """CMU-dev 13_39 (jumps in place off both feet), seed 0, as the development suite runs it, with
    WholeBodyConfig.pelvis_rate_share ``share``: the run's summary. Traced without steps to where he stands: in the rest
    after the clip such a step crosses the UHC distance at 3.38 s (docs/decisions.md, "Steps to where he stands"),
    after the jumps this test is about."""
    from stylesync.metrics.summary import summarize

    control = ControlConfig(whole_body=WholeBodyConfig(pelvis_rate_share=share))
    motion = MotionConfig(rest_step_min_m=None)
    return summarize(suite_run(f"bvh:{MOCAP / 'cmu-dev' / '13_39.bvh'}", 0, motion, control))


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "13_39.bvh").exists(), reason="../shared/mocap/cmu-dev is not present")
def test_a_jump_off_both_feet_is_followed_up_when_the_pelvis_rise_is_tracked():
    """The pelvis height's law with the target's rise on both feet (pelvis_rate_share 0.5) against the regulator
    alone. He springs up from his crouch in 0.43 s; under the damped regulator the character rose over 0.7 s and his
    pelvis went 0.5 m above the character's (the UHC termination, at about 1.4 s); tracking his rise, the character
    rises with him and is never that far from him. No fall either way."""
    regulated, tracked = _jump_run(0.0), _jump_run(0.5)
    assert not regulated["fell"] and not tracked["fell"]
    assert regulated["uhc_fall_time_s"] is not None and regulated["uhc_fall_time_s"] < 2.0, regulated["uhc_fall_time_s"]
    assert tracked["uhc_fall_time_s"] is None, tracked["uhc_fall_time_s"]


def test_a_joint_past_its_no_load_speed_gets_no_torque_along_its_motion():
    """limit_joint_speed: the torque along a fast joint's motion is removed where it would speed it up; a torque
    that brakes it or turns it across its motion is kept, and slower joints are untouched."""
    from stylesync.control.joint_speed_limit import limit_joint_speed

    vel = np.array([[40.0, 0.0, 0.0],   # fast, torque along: removed
                    [0.0, -50.0, 0.0],  # fast, torque against: kept (it brakes)
                    [20.0, 0.0, 0.0],   # slow: kept
                    [-35.0, 0.0, 0.0]])  # a hinge (column 0), fast, torque along its motion: removed
    tau = np.array([[10.0, 3.0, -2.0], [1.0, 5.0, 0.0], [10.0, 0.0, 0.0], [-7.0, 0.0, 0.0]])
    limited = tau.copy()
    assert limit_joint_speed(limited, vel, 30.0) == 2
    np.testing.assert_allclose(limited[0], [0.0, 3.0, -2.0])
    np.testing.assert_array_equal(limited[1:3], tau[1:3])
    np.testing.assert_allclose(limited[3], [0.0, 0.0, 0.0])
    assert limit_joint_speed(limited, vel, 60.0) == 0  # nothing over a higher limit


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_light_link_does_not_spin_up_within_a_control_tick():
    """The built-in dance_a, seed 2 (the development suite's settings): at 3.45-3.54 s a reference jump's torques,
    held over the control tick, spun the feet and hands to 26 m/s with the pelvis at 0.8 m: "the motion diverged"
    at 3.54 s (measured). With the joints' no-load speed the run completes its 12 s. Traced with Eq. 10's fraction
    by side after a step of the character's own (MotionConfig.fraction_needs_feet_in_his_order off) and every
    recovery step's nominal time (MotionConfig.recovery_swing_min_s None), with the pelvis height's regulator alone
    (WholeBodyConfig.pelvis_rate_share 0)."""
    def run(limit):
        control = ControlConfig(whole_body=WholeBodyConfig(joint_speed_limit_rad_s=limit, own_step_push_bound="off",
                                                            recovery_foot_target_rate="differenced",
                                                            pelvis_rate_share=0.0))
        # and before the pelvis came down as his swing went, and before a backward way made his raised rear foot a
        # stepping one
        motion = MotionConfig(fraction_needs_feet_in_his_order=False, recovery_swing_min_s=None,
                              swing_landing_within_reach=False, rear_foot_stepping_way_mps=None)
        return suite_run("builtin:dance_a", 2, motion, control)

    unlimited, limited = run(None), run(30.0)
    assert unlimited.fell and "diverged" in unlimited.fall_reason and unlimited.fall_time_s < 4.0
    assert not limited.fell


def _walk_with_attribution(attribute: bool) -> tuple[np.ndarray, list]:
    """The built-in walk's first 1.6 s (seed 0), ``plan_attribution`` called on every control tick from 1.2 s if
    ``attribute``: the final joint positions and the attributions."""
    cfg = SessionConfig(duration_s=1.6, operator=OperatorConfig(clip="walk"))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    plans: list = []
    last: dict = {}

    def tick(state, ref):
        last["q"] = state.joint_pos.copy()
        if attribute and state.time_s >= 1.2:
            plans.append((session.controller.plan_attribution(), session.controller.telemetry.com_force_n.copy(),
                          session.mass.total_kg))

    session.on_tick = tick
    session.run()
    return last["q"], plans


@pytest.mark.in_place
def test_the_plans_attribution_leaves_the_run_as_it_is_and_names_each_tasks_share():
    """WholeBodyController.plan_attribution solves the last QP again by a solver of its own: the run is the same bit
    for bit with it; the planned ground force carries the body's weight, and without the momentum task it no longer
    follows the force that task asks for."""
    q_plain, _ = _walk_with_attribution(False)
    q_attributed, plans = _walk_with_attribution(True)
    np.testing.assert_array_equal(q_plain, q_attributed)
    assert len(plans) > 20
    weight = plans[0][2] * 9.8
    errors_with, errors_without = [], []
    for plan, asked, _ in plans:
        forces = plan.ground_force_n
        assert {"", "posture", "pelvis_orientation", "centroidal_momentum"} <= set(forces)
        assert 0.6 * weight < forces[""][2] < 1.6 * weight
        errors_with.append(float(np.linalg.norm(forces[""][:2] - asked[:2])))
        errors_without.append(float(np.linalg.norm(forces["centroidal_momentum"][:2] - asked[:2])))
        assert plan.posture_cost.shape == plan.posture_desired_rad_s2.shape == plan.posture_planned_rad_s2.shape
        assert np.all(plan.posture_cost >= 0.0)
    assert np.median(errors_with) < 0.5 * np.median(errors_without), (np.median(errors_with),
                                                                        np.median(errors_without))

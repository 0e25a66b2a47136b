"""A rear sole on its toes (control/toe_contact.py): its rows keep the toe line where it is and leave the turn about
it free, its forces act at the front corners, a QP with it obeys the dynamics, and which feet go onto their toes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import suite_run

from stylesync import rotations as rot
from stylesync.config import ConfigError, ControlConfig, MotionConfig, WholeBodyConfig, follow_path
from stylesync.control.contacts import SOLE_CORNERS_IN_SOLE, SoleContact
from stylesync.control.formulation import WholeBodyFormulation
from stylesync.control.solver import DaqpSolver
from stylesync.control.tasks import JointPostureTask
from stylesync.control.toe_contact import (
    CONSTRAINT_ROWS,
    FORCES_PER_TOE,
    ToeContact,
    heel_raised,
    toe_off_sides,
)
from stylesync.control.whole_body import _TORQUE_LIMIT_FLAT
from stylesync.model.character import ANKLE_HEIGHT_M, N_DOFS, ROOT_DOFS
from stylesync.model.character_model import CharacterModel
from stylesync.model.sole import sole_corners_world


def _toe_mid_world(model: CharacterModel, frame: int) -> np.ndarray:
    p = model.frame_placement(frame)
    return p.translation + p.rotation @ SOLE_CORNERS_IN_SOLE[:2].mean(axis=0)


def test_the_rows_are_the_toe_lines_velocity_and_leave_its_turn_free(turned_model):
    """At a random velocity, the rows times v are the toe line's midpoint velocity (finite differences of the
    configuration) and the sole's angular velocity about its forward axis and the vertical; a turn of the sole about
    its own lateral axis alone meets the angular rows with zero."""
    model = turned_model
    q0, v0 = model.q.copy(), np.empty(model.nv)
    v0[model._perm] = model.v  # back to Pinocchio's layout, as update_qv takes it
    contact = ToeContact("left", 0.9, 45.0 * 9.8)
    contact.update(model)
    f = model.frame_id(contact.frame)
    rows, _ = contact.constraint_rows(10.0)
    assert rows.shape == (CONSTRAINT_ROWS, N_DOFS)
    rng = np.random.default_rng(1)
    v_pin = rng.normal(size=model.nv)  # Pinocchio's layout
    v_ours = v_pin.take(model._perm)
    dt = 1e-7
    p0 = _toe_mid_world(model, f)
    r0 = model.frame_placement(f).rotation.copy()
    model.update_qv(pin.integrate(model.model, q0, v_pin * dt), v0)
    p1 = _toe_mid_world(model, f)
    r1 = model.frame_placement(f).rotation.copy()
    model.update_qv(q0, v0)
    np.testing.assert_allclose(rows[:3] @ v_ours, (p1 - p0) / dt, rtol=1e-5, atol=1e-5)
    omega = pin.log3(r1 @ r0.T) / dt  # world axes
    np.testing.assert_allclose(rows[3:] @ v_ours, [r0[:, 0] @ omega, omega[2]], rtol=1e-5, atol=1e-5)
    lateral = r0[:, 1]
    pitch_only = np.concatenate([np.zeros(3), lateral])
    jac_ang = contact.jacobian[3:]
    v_pitch = np.linalg.lstsq(jac_ang, pitch_only[3:], rcond=None)[0]  # some joint motion turning the sole so
    np.testing.assert_allclose(jac_ang @ v_pitch, lateral, atol=1e-9)
    np.testing.assert_allclose(rows[3:] @ v_pitch, [0.0, lateral[2]], atol=1e-9)
    assert abs(lateral[2]) < 0.1  # a foot flat on the ground: its lateral axis is near horizontal


def test_the_forces_act_at_the_front_corners(turned_model):
    """The generator's columns are the front corners' Jacobians (the sole's, moved to the corner) times the pyramid
    edges; the normal row sums their normal parts."""
    model = turned_model
    contact = ToeContact("right", 0.9, 45.0 * 9.8)
    contact.update(model)
    assert contact.generator.shape == (N_DOFS, FORCES_PER_TOE)
    placement = model.frame_placement(model.frame_id(contact.frame))
    for c in range(2):
        lever = placement.rotation @ SOLE_CORNERS_IN_SOLE[c]
        np.testing.assert_allclose(contact.corners_world[c], placement.translation + lever, atol=1e-12)
        skew = np.array([[0, -lever[2], lever[1]], [lever[2], 0, -lever[0]], [-lever[1], lever[0], 0]])
        j_corner = contact.jacobian[:3] - skew @ contact.jacobian[3:]
        for e in range(4):
            np.testing.assert_allclose(contact.generator[:, 4 * c + e], j_corner.T @ contact.edges[e], atol=1e-9)
    assert contact.normal_row @ np.ones(FORCES_PER_TOE) == pytest.approx(2 * contact.edges[:, 2].sum())


def test_a_qp_with_one_sole_on_its_toes_obeys_the_dynamics_and_the_contacts(turned_model):
    """One flat sole and one on its toes: the solution satisfies the root's equations of motion, the toe line's rows
    and the flat sole's, with forces inside the pyramids that push on the body (sinking onto its feet)."""
    model = turned_model
    formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, (), 10.0, 0.05)
    posture = formulation.add_task(JointPostureTask(10.0, 0.05))
    posture.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)
    contacts = [SoleContact("left", 0.9, 45.0 * 9.8), ToeContact("right", 0.9, 45.0 * 9.8)]
    problem = formulation.build(model, contacts)
    assert problem.n_eq == ROOT_DOFS + 6 + CONSTRAINT_ROWS
    assert problem.H.shape == (N_DOFS + 16 + FORCES_PER_TOE,) * 2
    result = DaqpSolver().solve(problem)
    assert result.solved
    qdd, lam = result.x[:N_DOFS], result.x[N_DOFS:]
    gen = np.hstack([c.generator for c in contacts])
    residual = model.mass_matrix @ qdd + model.bias_forces - gen @ lam
    np.testing.assert_allclose(residual[:ROOT_DOFS], 0.0, atol=1e-6)
    for c in contacts:
        jac, acc = c.constraint_rows(10.0)
        np.testing.assert_allclose(jac @ qdd, acc, atol=1e-6)
    assert lam.min() >= -1e-9
    normal = float(contacts[0].normal_row @ lam[:16]) + float(contacts[1].normal_row @ lam[16:])
    assert normal > 0.1 * model.total_mass_kg * 9.8  # the soles push on the sinking body


def _flat_foot(x: float, y: float, yaw: float = 0.0, pitch: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    q = rot.multiply(rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), yaw),
                     rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), pitch))
    return np.array([x, y, ANKLE_HEIGHT_M]), q


def test_which_feet_go_onto_their_toes():
    """On two feet, the stretched leg behind the body goes onto its toes, the front one and a bent rear leg do not;
    on one foot none does; a raised heel behind the body stays on its toes, a raised heel in front does not."""
    left, ql = _flat_foot(0.0, 0.1)
    right, qr = _flat_foot(0.6, -0.1)
    ankles, quats = {"left": left, "right": right}, {"left": ql, "right": qr}
    com = np.array([0.45, 0.0, 0.8])
    both = ["left", "right"]
    assert toe_off_sides(both, {"left": 0.99, "right": 0.99}, com, ankles, quats, 0.97) == {"left"}
    assert toe_off_sides(both, {"left": 0.95, "right": 0.99}, com, ankles, quats, 0.97) == set()
    assert toe_off_sides(["left"], {"left": 0.99}, com, ankles, quats, 0.97) == set()
    # Turned round (the body goes the other way): the left foot is in front, the right one behind the body
    turned = {s: rot.quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi) for s in both}
    com_back = np.array([0.15, 0.0, 0.8])
    assert toe_off_sides(both, {"left": 0.99, "right": 0.99}, com_back, ankles, turned, 0.97) == {"right"}
    # A heel raised by 20° about the lateral axis (the toes down): on its toes whatever its leg
    _, raised = _flat_foot(0.0, 0.1, pitch=np.radians(20.0))
    assert heel_raised(sole_corners_world(left, raised)) and not heel_raised(sole_corners_world(left, ql))
    assert toe_off_sides(both, {"left": 0.5, "right": 0.5}, com, ankles, {"left": raised, "right": qr},
                         0.97) == {"left"}
    _, raised_front = _flat_foot(0.6, -0.1, pitch=np.radians(20.0))
    assert toe_off_sides(both, {"left": 0.5, "right": 0.5}, com, ankles, {"left": ql, "right": raised_front},
                         0.97) == set()


def test_the_setting_is_checked():
    assert WholeBodyConfig().toe_off_leg_stretch is None
    with pytest.raises(ConfigError):
        WholeBodyConfig(toe_off_leg_stretch=0.0)
    with pytest.raises(ConfigError):
        WholeBodyConfig(toe_off_leg_stretch=float("nan"))
    with pytest.raises(ConfigError):
        WholeBodyConfig(toe_off_min_way_speed_mps=-0.1)


MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
WALK = MOCAP / "deepmimic" / "humanoid3d_walk.txt"


def _walk_pelvis(stretch: float | None) -> tuple[bool, float, int]:
    """The development suite's walk, seed 2, with --follow-path's settings for 3.4 s and toe_off_leg_stretch
    ``stretch``: whether it fell, its pelvis's lowest height from 2.6 s on [m], and the ticks with a sole on its
    toes."""
    low, toes = [np.inf], [0]

    def watch(session):
        def tick(state, ref):
            if state.time_s >= 2.6:
                low[0] = min(low[0], float(state.root_pos_world[2]))
            toes[0] += bool(session.controller.on_toes)
        return tick

    def configure(cfg):
        return follow_path(cfg).replace(duration_s=3.4)

    control = ControlConfig(whole_body=WholeBodyConfig(toe_off_leg_stretch=stretch))
    result = suite_run(f"deepmimic:{WALK}", 2, MotionConfig(), control, watch=watch, configure=configure)
    return result.fell, low[0], toes[0]


@pytest.mark.pelvis_joint
@pytest.mark.skipif(not WALK.exists(), reason="../shared/mocap/deepmimic is not present")
def test_a_rear_foot_on_its_toes_keeps_the_pelvis_up_in_a_long_stride():
    """Traced on this walk: with flat soles the rear leg is straight from 2.77 s to its lift-off at 3.04 s while the
    pelvis passes over it, and the pelvis comes down from 0.81 m to below 0.7 m; with the rear sole on its toes its
    heel rises and the pelvis stays 8 cm or more higher. Neither falls."""
    flat_fell, flat_low, flat_toes = _walk_pelvis(None)
    toe_fell, toe_low, toe_toes = _walk_pelvis(0.97)
    assert not flat_fell and not toe_fell
    assert flat_toes == 0 and toe_toes > 10
    assert flat_low < 0.7, flat_low
    assert toe_low > flat_low + 0.08, (toe_low, flat_low)

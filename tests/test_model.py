"""The character model (Pinocchio) held against the engine: link poses and velocities, the COM, and the dynamics
(mass matrix, bias forces, gravity) through the accelerations the engine actually simulates; Jacobians and the
centroidal map against finite differences and the engine's link velocities."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.model.character import JOINT_DOF_COUNT, JOINT_DOF_START, JOINTS, LINK_NAMES, N_DOFS, JointKind
from stylesync.model.character_model import SOLE_FRAMES, CharacterModel
from stylesync.model.state import Torques
from stylesync.sim.pybullet_backend import PyBulletBackend

PHYSICS_HZ = 600.0


@pytest.fixture(scope="module")
def engine():
    backend = PyBulletBackend(WorldConfig(), PHYSICS_HZ)
    yield backend, CharacterModel(backend.body_description(), WorldConfig().gravity_mps2)
    backend.close()


def _random_pose(rng: np.random.Generator, spread: float = 0.4) -> np.ndarray:
    """Joint positions within the hinges' limits (knees bend backwards, elbows forwards)."""
    jp = np.zeros((len(JOINTS), 4))
    for k, j in enumerate(JOINTS):
        if j.kind is JointKind.BALL:
            jp[k] = rot.normalize(np.array([1.0, 0.0, 0.0, 0.0]) + spread * rng.normal(size=4))
        else:
            jp[k, 0] = -rng.uniform(0.2, 1.5) if "knee" in j.name else rng.uniform(0.2, 1.5)
    return jp


def _world_layout_velocity(state) -> np.ndarray:
    joints = [x for k, j in enumerate(JOINTS) for x in (state.joint_vel[k] if j.kind is JointKind.BALL
                                                           else state.joint_vel[k, :1])]
    return np.concatenate([state.root_lin_vel_world, state.root_ang_vel_world, joints])


def _place(backend, rng, velocities: bool, height: float = 3.0):
    backend.reset(np.array([0.2, -0.1, height]), rot.normalize(rng.normal(size=4)), _random_pose(rng))
    if velocities:
        jv = rng.normal(size=(len(JOINTS), 3))
        backend.set_velocities(rng.normal(size=3), rng.normal(size=3), jv)
    return backend.read_state(0.0)


def test_link_poses_velocities_and_com_match_engine(engine):
    backend, model = engine
    rng = np.random.default_rng(0)
    for _ in range(5):
        state = _place(backend, rng, velocities=True)
        model.update(state)
        np.testing.assert_allclose(model.link_positions(), state.link_origin_world, atol=1e-6)
        for i, name in enumerate(LINK_NAMES):
            f = model.frame_id(name)
            r_canonical = rot.matrix_from_quat(state.link_quat_wxyz[i])
            r_model = model.frame_rotation(f) @ rot.matrix_from_quat(rot.conjugate(
                rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), np.pi / 2)))
            np.testing.assert_allclose(r_model, r_canonical, atol=1e-6)
            np.testing.assert_allclose(model.frame_velocity(f)[3:], state.link_ang_vel_world[i], atol=1e-9)
        com = backend.mass_properties().com(state)
        np.testing.assert_allclose(model.com_world, com, atol=1e-6)
        np.testing.assert_allclose(model.com_vel_world, backend.mass_properties().com_velocity(state), atol=1e-6)
        assert model.total_mass_kg == pytest.approx(backend.mass_properties().total_kg, rel=1e-12)


def test_mass_matrix_symmetric_and_kinetic_energy(engine):
    backend, model = engine
    state = _place(backend, np.random.default_rng(1), velocities=True)
    model.update(state)
    m = model.mass_matrix
    np.testing.assert_allclose(m, m.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    # ½ vᵀ M v equals the sum of the links' kinetic energies (engine masses, inertias and velocities)
    mw = model.mass_matrix_world_layout()
    vw = _world_layout_velocity(state)
    ke = 0.5 * vw @ mw @ vw
    ke_pin = pin.computeKineticEnergy(model.model, model.data, model.q, model.velocity(
        model.q, state.root_lin_vel_world, state.root_ang_vel_world, state.joint_vel))
    assert ke == pytest.approx(ke_pin, rel=1e-12)


@pytest.mark.parametrize("seed", [2, 3, 4])
def test_dynamics_predict_the_engines_accelerations(engine, seed):
    """M q̈ + h(q, v) = τ: with random joint torques and gravity, at rest in the air, the model's accelerations
    are the ones the engine integrates over one step (M, gravity and the torques' frames all enter)."""
    backend, model = engine
    rng = np.random.default_rng(seed)
    state0 = _place(backend, rng, velocities=False)
    model.update(state0)
    tau = rng.normal(size=(len(JOINTS), 3)) * 3.0
    tau_flat = np.zeros(N_DOFS)
    for k, j in enumerate(JOINTS):
        if j.kind is not JointKind.BALL:
            tau[k, 1:] = 0.0
        a = 6 + JOINT_DOF_START[k]
        tau_flat[a:a + JOINT_DOF_COUNT[k]] = tau[k, :JOINT_DOF_COUNT[k]]
    backend.apply_torques(Torques(tau))
    backend.step()
    acc = (_world_layout_velocity(backend.read_state(0.0)) - _world_layout_velocity(state0)) * PHYSICS_HZ
    t = model.root_velocity_map()
    predicted = np.linalg.solve(model.mass_matrix_world_layout(), tau_flat - t.T @ model.bias_forces)
    np.testing.assert_allclose(predicted, acc, rtol=0, atol=1e-9 * max(1.0, np.abs(acc).max()))
    # at rest the bias forces are gravity alone
    np.testing.assert_allclose(model.bias_forces, model.gravity_forces, atol=1e-9)


def test_frame_and_com_jacobians_against_finite_differences(engine):
    backend, model = engine
    rng = np.random.default_rng(5)
    state = _place(backend, rng, velocities=True)
    model.update(state)
    q0 = model.q.copy()
    frames = [model.frame_id(n) for n in ("left_ankle", "right_wrist", "chest")] + [
        model.frame_id(n) for n in SOLE_FRAMES.values()]
    jacobians = {f: model.frame_jacobian(f) for f in frames}
    positions = {f: model.frame_position(f) for f in frames}
    rotations = {f: model.frame_rotation(f) for f in frames}
    j_com, com0 = model.com_jacobian.copy(), model.com_world.copy()
    eps = 1e-7
    perm = model._perm
    for i in range(N_DOFS):
        dv_pin = np.zeros(N_DOFS)
        dv_pin[perm[i]] = eps  # a step along DOF i of the character's layout, on the manifold
        q1 = pin.integrate(model.model, q0, dv_pin)
        model.update_qv(q1, np.zeros(N_DOFS))
        for f in frames:
            np.testing.assert_allclose((model.frame_position(f) - positions[f]) / eps, jacobians[f][:3, i],
                                       atol=1e-5)
            d_rot = pin.log3(rotations[f].T @ model.frame_rotation(f)) / eps  # local axes
            np.testing.assert_allclose(rotations[f] @ d_rot, jacobians[f][3:, i], atol=1e-5)
        np.testing.assert_allclose((model.com_world - com0) / eps, j_com[:, i], atol=1e-5)


def test_centroidal_map_gives_the_engines_momentum(engine):
    backend, model = engine
    state = _place(backend, np.random.default_rng(6), velocities=True)
    model.update(state)
    h = model.centroidal_map @ model.v
    masses = backend.mass_properties().link_mass_kg
    # the engine reports link states in single precision: 1e-6 relative
    np.testing.assert_allclose(h[:3], masses @ state.link_com_vel_world, rtol=1e-6, atol=1e-6)
    assert model.centroidal_map_dot_v.shape == (6,)


def test_drift_is_the_acceleration_at_zero_joint_acceleration(engine):
    """J̇ q̇ of a frame: its acceleration when q̈ = 0, from two evaluations a short time apart."""
    backend, model = engine
    state = _place(backend, np.random.default_rng(7), velocities=True)
    model.update(state)
    f = model.frame_id("left_sole")
    q0, v_pin = model.q.copy(), model.velocity(model.q, state.root_lin_vel_world, state.root_ang_vel_world,
                                               state.joint_vel)
    vel0, drift = model.frame_velocity(f), model.frame_drift(f)
    eps = 1e-6
    model.update_qv(pin.integrate(model.model, q0, v_pin * eps), v_pin)
    np.testing.assert_allclose((model.frame_velocity(f) - vel0) / eps, drift, atol=1e-3 * max(1, np.abs(drift).max()))

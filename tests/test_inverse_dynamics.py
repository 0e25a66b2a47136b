"""The floating-base Jacobians, the contact-force basis and the inverse-dynamics balance controller."""

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.control.contact_forces import (
    pyramid_edges,
    sole_corners_world,
    sole_touches,
    wrench_basis,
)
from stylesync.control.floating_jacobian import FloatingJacobians
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.stable_pd import flatten_joint_values
from stylesync.sim.factory import make_backend
from stylesync.model.character import ANKLE_HEIGHT_M, JOINTS, JointKind


@pytest.fixture(scope="module")
def moving_character():
    """The character in a random pose and random velocities, in the air."""
    b = make_backend(WorldConfig(), 600.0)
    rng = np.random.default_rng(1)
    q = np.zeros((len(JOINTS), 4))
    for k, j in enumerate(JOINTS):
        if j.kind is JointKind.BALL:
            q[k] = rot.quat_from_rotvec(rng.normal(0.0, 0.4, 3))
        else:
            q[k, 0] = rng.uniform(-1.0, 0.2)
    b.reset(np.array([0.1, 0.2, 1.5]), rot.quat_from_rotvec(np.array([0.2, -0.3, 0.7])), q)
    b.set_velocities(rng.normal(0.0, 1.0, 3), rng.normal(0.0, 1.0, 3),  # type: ignore[attr-defined]
                     rng.normal(0.0, 1.0, (len(JOINTS), 3)))
    yield b, b.read_state(0.0)
    b.close()


def _qdot(state):
    return np.concatenate([state.root_lin_vel_world, state.root_ang_vel_world, flatten_joint_values(state.joint_vel)])


def test_point_jacobians_give_the_engines_link_velocities(moving_character):
    b, s = moving_character
    jac = FloatingJacobians(s, JointFrames(s))
    qd = _qdot(s)
    for i in range(len(s.link_com_world)):
        np.testing.assert_allclose(jac.point_linear(i, s.link_com_world[i]) @ qd, s.link_com_vel_world[i], atol=1e-6)
        np.testing.assert_allclose(jac.angular(i) @ qd, s.link_ang_vel_world[i], atol=1e-6)


def test_momentum_jacobian_matches_the_engines_mass_matrix(moving_character):
    """The linear-momentum rows of M q̇ are Σ m_i v_i: the Jacobians and the mass matrix share one layout."""
    b, s = moving_character
    mass = b.mass_properties()
    jac = FloatingJacobians(s, JointFrames(s))
    qd = _qdot(s)
    p = mass.link_mass_kg @ s.link_com_vel_world
    np.testing.assert_allclose(jac.mass_weighted_linear(s.link_com_world, mass.link_mass_kg) @ qd, p, atol=1e-5)
    np.testing.assert_allclose((b.joint_space_inertia() @ qd)[:3], p, atol=1e-3)
    # The gravity force without the Jacobian: its transpose times a vertical g.
    np.testing.assert_allclose(jac.gravity_force(s.link_com_world, mass.link_mass_kg, 9.8),
                               jac.mass_weighted_linear(s.link_com_world, mass.link_mass_kg).T @ [0.0, 0.0, 9.8],
                               rtol=1e-12, atol=1e-9)


def test_wrench_basis_forces_stay_in_the_friction_cone_and_on_the_sole():
    corners = {"left": sole_corners_world(np.array([0.0, 0.1, ANKLE_HEIGHT_M]), np.array([1.0, 0.0, 0.0, 0.0]))}
    com = np.array([0.05, 0.0, 0.9])
    edges, a = wrench_basis(com, corners, friction=0.9)
    assert np.allclose(np.linalg.norm(edges, axis=1), 1.0)
    assert np.all(np.hypot(edges[:, 0], edges[:, 1]) <= 0.9 * edges[:, 2] + 1e-12)
    assert np.allclose(corners["left"][:, 2], 0.0, atol=1e-9)  # the corners lie on the ground plane
    points = np.repeat(corners["left"], 4, axis=0)
    dirs = np.tile(edges, (4, 1))
    np.testing.assert_allclose(a[:3].T, dirs)
    np.testing.assert_allclose(a[3:].T, np.cross(points - com, dirs))
    # any non-negative mix has its centre of pressure inside the sole
    lam = np.random.default_rng(0).uniform(0.0, 1.0, a.shape[1])
    f = a[:3] @ lam
    cop = (points[:, :2] * (dirs[:, 2] * lam)[:, None]).sum(axis=0) / f[2]
    xs, ys = corners["left"][:, 0], corners["left"][:, 1]
    assert xs.min() <= cop[0] <= xs.max() and ys.min() <= cop[1] <= ys.max()
    assert len(pyramid_edges(0.9)) == 4


def test_standing_character_bears_arm_waving_and_a_squat():
    """Double stance with a moving upper body and a deep knee bend (the cases the Jacobian-transpose mapping fell
    on): no fall, and the squat ends in double stance."""
    from stylesync.experiments import push, squat_jump
    from stylesync.motion.stance_fsm import Stance
    from stylesync.session import STANCE_CODE

    wave = push.run_one("wave", 2.0, seed=0)
    assert not wave.fell, wave.fall_reason
    squat = squat_jump.run_one("squat", 1.75, seed=0)
    assert not squat.fell, squat.fall_reason
    assert squat.log.array("char_state")[-1] == STANCE_CODE[Stance.DS]


def test_desired_horizontal_force_is_limited_to_what_the_soles_can_give():
    """Eq. 21's pendulum: a COM above the middle of the support may be pushed either way, by at most
    m g / h times the distance to the support's (margined) edge plus the angular-momentum allowance; a COM
    behind the heels can be brought back only by that allowance; the vertical force is untouched."""
    from stylesync.control.contact_forces import (
        COP_MARGIN,
        MOMENTUM_ACCEL_ALLOWANCE_MPS2,
        feasible_horizontal_force,
    )

    corners = {"left": sole_corners_world(np.array([0.0, 0.1, ANKLE_HEIGHT_M]), rot.IDENTITY_WXYZ),
               "right": sole_corners_world(np.array([0.0, -0.1, ANKLE_HEIGHT_M]), rot.IDENTITY_WXYZ)}
    pts = np.concatenate(list(corners.values()))
    lo, hi = pts[:, 0].min(), pts[:, 0].max()
    mid, half = 0.5 * (lo + hi), 0.5 * COP_MARGIN * (hi - lo)
    m, g, h = 45.0, 9.8, 0.9
    com = np.array([mid, 0.0, h])
    big = np.array([1000.0, 0.0, 441.0])
    f = feasible_horizontal_force(big, com, corners, m, g)
    assert f[0] == pytest.approx(m * g / h * half + m * MOMENTUM_ACCEL_ALLOWANCE_MPS2)
    assert f[2] == 441.0
    f_back = feasible_horizontal_force(-big, com, corners, m, g)
    assert f_back[0] == pytest.approx(-f[0])
    small = np.array([5.0, -3.0, 441.0])
    assert np.allclose(feasible_horizontal_force(small, com, corners, m, g), small)
    behind = np.array([lo - 0.2, 0.0, h])  # behind the heels: forwards, only the allowance
    f_out = feasible_horizontal_force(big, behind, corners, m, g)
    assert f_out[0] == pytest.approx(m * MOMENTUM_ACCEL_ALLOWANCE_MPS2)


def test_a_planted_sole_just_unloaded_still_supports_and_a_lifted_one_does_not():
    gap = 0.003
    flat = rot.IDENTITY_WXYZ
    on_ground = np.array([0.0, 0.0, ANKLE_HEIGHT_M])
    assert sole_touches(on_ground, flat, False, gap)  # flat on the ground, no load yet
    assert sole_touches(on_ground + [0, 0, 0.5 * gap], flat, False, gap)
    assert not sole_touches(on_ground + [0, 0, 2.0 * gap], flat, False, gap)
    assert sole_touches(on_ground + [0, 0, 0.05], flat, True, gap)  # pressing: in contact whatever the geometry says
    # Tilted 10° about the foot's long axis, the ankle 1 cm up: one sole edge is still down.
    tilted = rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(10.0))
    assert sole_touches(on_ground + [0, 0, 0.005], tilted, False, gap)
    assert not sole_touches(on_ground, flat, False, 0.0)  # the rule switched off: only pressing counts


def test_warm_started_nnls_reaches_the_same_minimiser_as_scipy():
    # Strictly convex problems (a ridge of 0.01 as in the force plan): the minimiser is unique, so a cold start, a
    # random warm start and the right warm start must all give SciPy's answer; the right one in one solve.
    from scipy.optimize import nnls

    from stylesync.control.nnls import nnls_gram

    rng = np.random.default_rng(3)
    for _ in range(300):
        m, n = int(rng.integers(20, 80)), int(rng.integers(4, 40))
        a = np.vstack([rng.normal(size=(m, n)), 0.01 * np.eye(n)])
        b = np.concatenate([3.0 * rng.normal(size=m), np.zeros(n)])
        expected, _ = nnls(a, b, maxiter=50 * n)
        scale = max(1.0, float(np.abs(expected).max()))
        gram, rhs = a.T @ a, a.T @ b
        cold, free = nnls_gram(gram, rhs)
        random_start, _ = nnls_gram(gram, rhs, rng.random(n) < 0.5)
        warm, _ = nnls_gram(gram, rhs, free, max_iter=1)
        for x in (cold, random_start, warm):
            assert np.all(x >= 0.0)
            np.testing.assert_allclose(x, expected, atol=1e-8 * scale)
        assert np.array_equal(free, expected > 0.0)

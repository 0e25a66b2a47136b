"""Physics behaviour with clear numeric bounds."""

import numpy as np
from conftest import random_pose

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.control.contacts import sole_corners_world
from stylesync.control.gravity_compensation import gravity_torques
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.pid import joint_error
from stylesync.model.character import STANDING_ROOT_HEIGHT_M
from stylesync.model.state import Torques
from stylesync.sim.factory import make_backend


def test_gravity_compensation_holds_root_fixed_character_5s():
    b = make_backend(WorldConfig(), 600.0, fixed_root=True)
    q0 = random_pose(1, hinge_rad=0.5)
    b.reset(np.array([0, 0, 1.5]), rot.IDENTITY_WXYZ, q0)
    m = b.mass_properties()
    for i in range(3000):
        s = b.read_state(i / 600)
        b.apply_torques(Torques(gravity_torques(s, JointFrames(s), m.link_mass_kg, 9.8, {"left": 0, "right": 0}, {})))
        b.step()
    err = np.degrees(np.linalg.norm(joint_error(b.read_state(5.0).joint_pos, q0), axis=1))
    b.close()
    assert err.max() < 1.0


def test_sole_lies_ankle_height_below_the_ankle_joint():
    """The model's foot box reaches ANKLE_HEIGHT_M below the ankle joint: the straight character touches the ground
    when its root is lowered 2 mm below STANDING_ROOT_HEIGHT_M and not when raised 2 mm above it."""
    for dz, touches in ((-0.002, True), (0.002, False)):
        b = make_backend(WorldConfig(), 600.0, fixed_root=True)
        b.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M + dz]), rot.IDENTITY_WXYZ)
        b.step()
        s = b.read_state(1 / 600)
        b.close()
        for side in ("left", "right"):
            i = s.link(f"{side}_ankle")
            corners = sole_corners_world(s.link_origin_world[i], s.link_quat_wxyz[i])
            assert np.allclose(corners[:, 2], dz, atol=1e-3)
        assert s.feet_pressing() == {"left": touches, "right": touches}


def test_a_diverged_motion_counts_as_a_fall_even_in_the_air():
    # A controller that runs away can whip the body into the air (in the bench, one run was launched 50 m: the
    # engine clamps joint speeds at 100 rad/s, which does not conserve momentum). Neither fall test (pelvis low, a
    # non-foot contact) sees a body in the air; a link faster than any human limb, or a pelvis above any jump, does.
    from stylesync.session import DIVERGED_LINK_SPEED_MPS, DIVERGED_ROOT_HEIGHT_M, Session

    b = make_backend(WorldConfig(), 600.0)
    b.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M]), np.array([1.0, 0.0, 0.0, 0.0]))
    s = b.read_state(0.0)
    b.close()
    assert Session._fall_reason(s) == ""
    s.link_com_vel_world[5] = [0.0, DIVERGED_LINK_SPEED_MPS + 1.0, 0.0]
    assert "diverged" in Session._fall_reason(s)
    s.link_com_vel_world[5] = 0.0
    s.root_pos_world[2] = DIVERGED_ROOT_HEIGHT_M + 0.1
    assert "diverged" in Session._fall_reason(s)

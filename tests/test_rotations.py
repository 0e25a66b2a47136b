import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from stylesync import rotations as rot

quats = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda v: np.linalg.norm(v) > 0.1)


@given(quats)
@settings(max_examples=100)
def test_round_trips(v):
    q = rot.normalize(np.array(v))
    assert np.allclose(rot.wxyz_from_xyzw(rot.xyzw_from_wxyz(q)), q)
    q2 = rot.quat_from_matrix(rot.matrix_from_quat(q))
    assert min(np.abs(q2 - q).max(), np.abs(q2 + q).max()) < 1e-9  # double cover
    r = rot.quat_from_rotvec(rot.rotvec_from_quat(q))
    assert np.allclose(rot.matrix_from_quat(r), rot.matrix_from_quat(q), atol=1e-9)
    r1, r2 = rot.quat_from_rotvec(rot.rotvec_from_quat(q)), rot.quat_from_rotvec(rot.rotvec_from_quat(-q))
    assert np.allclose(rot.matrix_from_quat(r1), rot.matrix_from_quat(r2), atol=1e-9)  # q and -q: one rotation


def test_batched_slerp_matches_the_single_one():
    rng = np.random.default_rng(3)
    q0 = rng.normal(size=(32, 4))
    q1 = rng.normal(size=(32, 4))
    q0 /= np.linalg.norm(q0, axis=1, keepdims=True)
    q1 /= np.linalg.norm(q1, axis=1, keepdims=True)
    q1[0] = q0[0]  # no rotation between them
    q1[1] = -q0[1]  # the same rotation, other sign
    for t in (0.0, 0.25, 0.5, 1.0):
        single = np.array([rot.slerp(a, b, t) for a, b in zip(q0, q1, strict=True)])
        assert np.abs(rot.batch_slerp(q0, q1, t) - single).max() < 1e-12


def test_batched_product_and_matrix_match_the_single_ones():
    rng = np.random.default_rng(5)
    a = rng.normal(size=(32, 4))
    b = rng.normal(size=(32, 4))
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    for i in range(32):
        assert np.abs(rot.batch_multiply(a, b)[i] - rot.multiply(a[i], b[i])).max() < 1e-12
        assert np.abs(rot.batch_matrix_from_quat(a)[i] - rot.matrix_from_quat(a[i])).max() < 1e-12


def test_batched_style_features_match_the_extractor():
    from stylesync.motion.style_features import StyleExtractor, style_rows

    rng = np.random.default_rng(7)
    n = 64
    hip = rng.normal(size=(n, 2, 3))
    knee = hip + 0.3 * rng.normal(size=(n, 2, 3))
    ankle = knee + 0.3 * rng.normal(size=(n, 2, 3))
    ankle[:8] = knee[:8] + (knee[:8] - hip[:8])  # straight legs: the plane falls back to the pelvis's left
    quats = rng.normal(size=(n, 5, 4))
    quats /= np.linalg.norm(quats, axis=2, keepdims=True)
    shank, foot, pelvis = quats[:, 0:2], quats[:, 2:4], quats[:, 4]
    com = rng.normal(size=(n, 3))
    rows = style_rows(hip, knee, ankle, shank, foot, com, pelvis)
    sides = ("left", "right")
    for i in range(n):
        f = StyleExtractor()(*({s: x[i, k] for k, s in enumerate(sides)} for x in (hip, knee, ankle, shank, foot)),
                             com[i], pelvis[i])
        assert np.abs(rows[i] - np.array(f.as_row())).max() < 1e-12


def test_joint_map_local_rotations_are_each_pairs_relative_rotation():
    from stylesync.processing.joint_map import JOINT_MAP, local_rotations

    rng = np.random.default_rng(7)
    names = {n for pair in JOINT_MAP.values() for n in pair}
    world = {n: rot.normalize(rng.normal(size=4)) for n in names}
    level = rot.normalize(rng.normal(size=4))
    joints = tuple(JOINT_MAP)
    out = local_rotations(world, joints, {"chest": level})
    for j, q in zip(joints, out, strict=True):
        child, parent = JOINT_MAP[j]
        q_parent = level if j == "chest" else world[parent]
        # q_parent ⊗ local = q_child
        np.testing.assert_allclose(rot.multiply(q_parent, q), world[child], atol=1e-12)
    np.testing.assert_allclose(rot.batch_slerp(out, out[::-1], 1.0), rot.batch_align_sign(out[::-1], out), atol=1e-12)


def test_heading_is_the_turn_about_the_vertical_of_a_trunk_bent_over():
    # A pelvis turned by psi about the vertical, then pitched by theta: its heading is psi at every pitch up to the
    # twist's tilt (past the vertical too); the heading of its forward axis turns half a turn as that axis passes
    # the vertical. Beyond that tilt (a body upside down) the forward axis's heading again.
    for psi in np.radians([-179.0, -120.0, -30.0, 0.0, 45.0, 135.0, 180.0]):
        for theta_deg in (0.0, 30.0, 60.0, 80.0, 89.0, 91.0, 99.0, 120.0):
            q = rot.multiply(rot.quat_from_yaw(psi),
                             rot.quat_from_axis_angle(np.array([0.0, 1.0, 0.0]), np.radians(theta_deg)))
            wrapped = np.angle(np.exp(1j * (rot.heading_from_quat(q) - psi)))
            upright = theta_deg < rot.HEADING_TWIST_MAX_TILT_DEG
            assert abs(wrapped) < 1e-9 if upright else abs(abs(wrapped) - np.pi) < 1e-9
            forward = np.angle(np.exp(1j * (rot.yaw_from_quat(q) - psi)))
            assert abs(forward) < 1e-9 if theta_deg < 90.0 else abs(abs(forward) - np.pi) < 1e-9
    assert rot.heading_from_quat(-rot.quat_from_yaw(0.7)) == rot.heading_from_quat(rot.quat_from_yaw(0.7))


def test_heading_is_the_forward_axis_yaw_bit_for_bit_while_upright_and_continuous_beyond():
    rng = np.random.default_rng(11)
    q = rng.normal(size=(4000, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    batch = rot.batch_heading_from_quat(q)
    upright = 0
    for i in range(len(q)):
        single = rot.heading_from_quat(q[i])
        assert abs(np.angle(np.exp(1j * (batch[i] - single)))) < 1e-12
        r = rot.matrix_from_quat(q[i])
        if np.hypot(r[0, 0], r[1, 0]) >= np.cos(np.radians(rot.HEADING_FORWARD_PITCH_DEG)):
            assert single == rot.yaw_from_quat(q[i])  # the Euler yaw as it was
            upright += 1
    assert upright > 500
    # Along a pitch from upright to 99 degrees (bent over past the vertical) at a turn psi with a roll: no jump of
    # more than a degree a step
    for psi in (0.3, 2.9):
        for phi_deg in (0.0, 20.0):
            last = None
            for theta_deg in np.arange(0.0, 99.0, 0.5):
                q = rot.multiply(rot.multiply(rot.quat_from_yaw(psi), rot.quat_from_axis_angle(
                    np.array([0.0, 1.0, 0.0]), np.radians(theta_deg))),
                    rot.quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(phi_deg)))
                h = rot.heading_from_quat(q)
                if last is not None:
                    assert abs(np.angle(np.exp(1j * (h - last)))) < np.radians(1.0)
                last = h


def test_the_spins_heading_does_not_jump_where_his_trunk_bends_over():
    # The humanoid3d spin (pybullet_data): his trunk bends over as he turns (the pelvis's forward axis within 5
    # degrees of straight down at times, its tilt up to 95 degrees), and the clip turns at most 372 deg/s (6.2
    # degrees a sample at 60 Hz). His heading (the style feature H, which the character's root follows, Sec. 5.4)
    # moves at most 14.4 degrees a sample (where the pelvis is tilted 90 degrees its turn about the vertical itself
    # moves that fast); the forward axis's heading jumps by up to 83 degrees.
    from stylesync.config import ClockConfig, OperatorConfig
    from stylesync.motion.style_features import StyleExtractor
    from stylesync.sources.builtin_operator import builtin_operator

    _, performer = builtin_operator(OperatorConfig(clip="spin", start_ramp_s=0.0), ClockConfig(), 6.0, 0)
    dt_s = 1.0 / 60.0
    heading, forward = [], []
    for t in np.arange(1.0, 5.4, dt_s):
        f = performer.frame_at(float(t))
        sides = {"left": "LEFT", "right": "RIGHT"}
        feats = StyleExtractor()({k: f.pos(f"HIP_{v}") for k, v in sides.items()},
                                 {k: f.pos(f"KNEE_{v}") for k, v in sides.items()},
                                 {k: f.pos(f"ANKLE_{v}") for k, v in sides.items()},
                                 {k: f.quat(f"KNEE_{v}") for k, v in sides.items()},
                                 {k: f.quat(f"ANKLE_{v}") for k, v in sides.items()},
                                 f.pos("PELVIS"), f.quat("PELVIS"))
        heading.append(feats.H)
        forward.append(rot.yaw_from_quat(f.quat("PELVIS")))
    step_deg = np.degrees(np.abs(np.diff(np.unwrap(heading))))
    jump_deg = np.degrees(np.abs(np.diff(np.unwrap(forward))))
    assert step_deg.max() < 15.0
    assert jump_deg.max() > 45.0  # the forward axis's heading is not one
    assert np.degrees(abs(np.unwrap(heading)[-1] - np.unwrap(heading)[0])) > 600.0  # two turns, as the clip's

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

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

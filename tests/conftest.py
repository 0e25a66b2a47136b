import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import JOINTS, JointKind


def random_pose(seed: int, ball_sigma_rad: float = 0.3, hinge_rad: float = 0.6) -> np.ndarray:
    """A reproducible joint pose (n_joints, 4): random ball rotations, knees flexed, elbows bent."""
    rng = np.random.default_rng(seed)
    q = np.zeros((len(JOINTS), 4))
    for k, j in enumerate(JOINTS):
        if j.kind is JointKind.BALL:
            q[k] = rot.quat_from_rotvec(rng.normal(0, ball_sigma_rad, 3))
        else:
            q[k, 0] = -hinge_rad if "knee" in j.name else hinge_rad
    return q

"""Balance strategy (Sec. 5.4): level root with heading H, stance-hip blend (Eq. 11), swing-hip feedback (Eq. 12).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot


def level_root(heading_rad: float) -> np.ndarray:
    """Sec. 5.4: pelvis transverse plane parallel to the ground, yaw = heading of COM H."""
    return rot.quat_from_yaw(heading_rad)


def stance_hip_blend(q_reference: np.ndarray, q_current: np.ndarray, w0: float) -> np.ndarray:
    """Eq. 11, ``q_d = q_r^{w0} · q_c^{1-w0}``, read as slerp(q_c, q_r, w0) (a product of quaternion powers is
    not a rotation blend)."""
    return rot.slerp(q_current, q_reference, w0)


def swing_hip_feedback(q_thigh_world: np.ndarray, d_desired: np.ndarray, d_feedback: np.ndarray,
                       v_desired: np.ndarray, v_feedback: np.ndarray, cd: float, cv: float,
                       heading_rad: float) -> np.ndarray:
    """Eq. 12, SIMBICON swing-hip law on the swing thigh's world orientation, per horizontal DOF in the
    heading frame.

    The sign follows SIMBICON [2]: when the COM is further ahead of the stance foot (or faster) than desired,
    the swing leg reaches further forward. With c_d = c_v = 0 (Sec. 7.2) the reference passes unchanged.
    """
    if cd == 0.0 and cv == 0.0:
        return q_thigh_world
    R_h = rot.matrix_from_quat(rot.quat_from_yaw(heading_rad))
    dd = R_h.T @ (np.asarray(d_feedback) - np.asarray(d_desired))
    dv = R_h.T @ (np.asarray(v_feedback) - np.asarray(v_desired))
    forward = cd * dd[0] + cv * dv[0]  # swing thigh further forward [rad]
    lateral = cd * dd[1] + cv * dv[1]  # swing thigh further to the left [rad]
    # Forward swing of a thigh hanging along -z is a rotation about -y; leftward, about +x.
    delta_world = R_h @ np.array([lateral, -forward, 0.0])
    return rot.multiply(rot.quat_from_rotvec(delta_world), q_thigh_world)

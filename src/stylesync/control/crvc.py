"""COM and root virtual control, CR-VC (Sec. 6.2, Eq. 16-18).

* COM virtual force (Eq. 16, 17): ``f_r = m_C (Kp_vf e_p + Kd_vf e_v)``, realised through the stance leg(s) by
  the Jacobian transpose of the COM with the stance foot as base. Table 3 gives Kp = 50, Kd = 30 (its second
  "Kp" column read as Kd); as plain N/m these could not move a 45 kg body (2.5 N for 5 cm), so we read them as
  gains per unit mass, i.e. acceleration gains [1/s^2], [1/s].
* Root virtual torque (Eq. 16): ``τ_r = Kp_vt e_q + Kd_vt e_ω`` on the pelvis orientation, realised as internal
  torques on the stance hip(s) (SIMBICON [2]): a hip torque τ acts +τ on the thigh and -τ on the pelvis, so each
  stance hip receives ``-w τ_r`` (w its stance weight). Eq. 18 then sums the parts. Table 3's Kp = 5000,
  Kd = 1000 ask for torques the feet cannot pass to the ground (a 45 kg body standing on 18 cm feet can resist
  about 20 N·m before a foot rolls): 1 degree of pelvis tilt already gives 87 N·m, the feet roll and the character
  falls within a second (measured). Defaults are Kp = 1000, Kd = 100 (SIMBICON's torso range).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.control.gravity_compensation import LEG_JOINTS, SUBTREE_MASK
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.model.character import JOINT_DOF_START, JOINTS, N_JOINT_DOFS, Q_WORLD_MODEL

HIP_JOINT = {side: next(k for k, j in enumerate(JOINTS) if j.name == f"{side}_hip") for side in ("left", "right")}


def com_virtual_force(com_desired, com_vel_desired, com, com_vel, mass_kg: float, kp: float, kd: float):
    """Eq. 16 (first line) with Eq. 19 errors [N]."""
    return mass_kg * (kp * (np.asarray(com_desired) - com) + kd * (np.asarray(com_vel_desired) - com_vel))


def stance_force_torques(frames: JointFrames, link_com_world: np.ndarray, link_mass_kg: np.ndarray,
                         force_world: np.ndarray, stance_weight: dict[str, float]) -> np.ndarray:
    """Eq. 17 in the joint-torque layout (see :func:`stance_force_moments`)."""
    return frames.torque_from_moment(stance_force_moments(frames, link_com_world, link_mass_kg, force_world,
                                                          stance_weight))


def stance_force_moments(frames: JointFrames, link_com_world: np.ndarray, link_mass_kg: np.ndarray,
                         force_world: np.ndarray, stance_weight: dict[str, float]) -> np.ndarray:
    """Eq. 17 as world moments (n_joints, 3): ``τ_fr = J_r^T f_r`` through each stance leg (foot as base),
    weighted by its stance share.

    J_r is the Jacobian of the whole-body COM with the stance foot fixed: turning a leg joint j moves only the
    links above it, so its column is ``(M_above / M) ω_j × (c_above - o_j)``.
    """
    moment = np.zeros((len(JOINTS), 3))
    m_all = link_mass_kg.sum()
    weighted = link_mass_kg[:, None] * link_com_world
    for side, w in stance_weight.items():
        if w <= 0:
            continue
        idx = LEG_JOINTS[side]
        m_sub = SUBTREE_MASK[idx] @ link_mass_kg
        c_sub = (SUBTREE_MASK[idx] @ weighted) / m_sub[:, None]
        m_above = m_all - m_sub
        c_above = (weighted.sum(axis=0)[None, :] - m_sub[:, None] * c_sub) / m_above[:, None]
        moment[idx] += -w * (m_above / m_all)[:, None] * rot.cross(c_above - frames.origin[idx], force_world[None, :])
    return moment


def root_virtual_torque(q_root_desired, q_root, ang_vel_world, kp: float, kd: float, yaw_scale: float,
                        predict_dt_s: float = 0.0) -> np.ndarray:
    """Eq. 16 (second line): world-frame PD torque [N·m] on the pelvis orientation. With ``predict_dt_s`` the
    orientation error is taken one step ahead (the explicit part of the stable PD, stable_pd.py)."""
    return root_pd(root_orientation_error(q_root_desired, q_root), ang_vel_world, kp, kd, yaw_scale, predict_dt_s)


def root_orientation_error(q_root_desired, q_root) -> np.ndarray:
    """World-frame rotation vector [rad] from the pelvis orientation to the desired one (Eq. 16's error)."""
    return rot.rotvec_from_quat(rot.multiply(q_root_desired, rot.conjugate(q_root)))


def root_pd(error_rotvec: np.ndarray, ang_vel_world, kp: float, kd: float, yaw_scale: float,
            predict_dt_s: float = 0.0) -> np.ndarray:
    """Eq. 16's PD law on a root orientation error (:func:`root_orientation_error`) [gains' units times rad]."""
    omega = np.asarray(ang_vel_world, dtype=float)
    return root_gain_scale(yaw_scale) * (kp * (error_rotvec - predict_dt_s * omega) - kd * omega)


def root_gain_scale(yaw_scale: float) -> np.ndarray:
    """Per-axis scaling of the root gains (world x, y, z): the heading axis may be scaled separately."""
    return np.array([1.0, 1.0, yaw_scale])


def stance_hip_map(q_root: np.ndarray, hip_quat_model: dict[str, np.ndarray],
                   stance_weight: dict[str, float]) -> np.ndarray:
    """S (N_JOINT_DOFS, 3): joint-DOF torques that give the pelvis a world torque τ_r through the stance hips.

    Each stance hip gets ``-w R_thigh^T τ_r`` in its child (thigh) frame (a hip torque acts -τ on the pelvis).
    """
    s_map = np.zeros((N_JOINT_DOFS, 3))
    q_pelvis_model = rot.multiply(q_root, Q_WORLD_MODEL)
    for side, w in stance_weight.items():
        if w <= 0:
            continue
        k = HIP_JOINT[side]
        r_thigh = rot.matrix_from_quat(rot.multiply(q_pelvis_model, hip_quat_model[side]))
        s_map[JOINT_DOF_START[k]:JOINT_DOF_START[k] + 3] = -w * r_thigh.T
    return s_map

"""The balance and synchronisation controller (Sec. 6) realised by contact-consistent inverse dynamics.

Same parts as controller.py, the same gains where the paper gives them, realised differently:

* COM virtual force (Eq. 16, first line, with Eq. 19 errors; Table 3 gains per unit mass) plus the LIPM
  time-sync force (Eq. 21-23, bounded by Eq. 26), and the root virtual torque (Eq. 16, second line) make one
  desired wrench on the body about its COM;
* the ground forces closest to it that the soles can pass (contact_forces.py) replace the Jacobian-transpose
  mapping of Eq. 17-18 and the IPM ankle torque of Eq. 20 (a centre of pressure is now placed, not implied);
* gravity (Eq. 14-15) is in the bias force of the inverse dynamics, with the stance feet's reactions;
* each joint's PD (Eq. 13) sets a desired joint acceleration, ``q̈* = ω² e + 2 ζ ω ė`` (gains per unit inertia,
  so that the light feet and hands and the heavy trunk track alike);
* the torques are those of the floating body's equations of motion with those forces (inverse_dynamics.py).

Why: Eq. 17-18 assume the body is static and every stance foot can push as asked. Measured with that mapping,
the standing character toppled when it waved its arms, a symmetric squat rolled a foot at the bottom, and the
walk fell within a second of its first step (docs/decisions.md). Here a foot's centre of pressure never leaves
its sole, the swing of the arms is paid for by the whole body's momentum, and the stance legs' torques are
consistent with the feet staying where they are.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ControlConfig
from stylesync.control import bounds as bnd
from stylesync.control.contact_forces import ContactForces, regularisation, sole_corners_world, wrench_basis
from stylesync.control.controller import TORQUE_LIMIT, ControlTelemetry
from stylesync.control.crvc import com_virtual_force, root_virtual_torque
from stylesync.control.floating_jacobian import FloatingJacobians
from stylesync.control.inverse_dynamics import joint_torques, solve_with_contact_forces
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.model_compensation import bounded_lipm_sync_force
from stylesync.control.pid import JointPid, joint_error, reference_velocity
from stylesync.control.stable_pd import N_DOFS, flatten_joint_values, unflatten_joint_values
from stylesync.motion.reference import ReferencePose
from stylesync.sim.backend import CONTACT_FORCE_N, CharacterState, JointFeedback, MassProperties, Torques
from stylesync.sim.character import ANKLE_HEIGHT_M, JOINTS, LINK_NAMES, JointKind

_FOOT_LINK = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
_IS_BALL = np.array([j.kind is JointKind.BALL for j in JOINTS])
GROUND_PRESS_M = 0.02  # a stance foot not yet touching is aimed this far below the ground [m]
FOOT_TASK_WEIGHT = 100.0  # weight of that foot's height task against a joint's


class MomentumBalanceController:
    def __init__(self, cfg: ControlConfig, mass: MassProperties, gravity_mps2: float, physics_dt_s: float,
                 control_dt_s: float, bounds: bnd.BoundsMonitor | None = None, friction: float = 0.9):
        self.cfg = cfg
        self.mass = mass
        self.g = gravity_mps2
        self.friction = friction
        self.control_dt_s = control_dt_s
        self.pid = JointPid(cfg, physics_dt_s)  # its integral is unused here; kept for the common reset
        self.bounds = bounds if bounds is not None else bnd.BoundsMonitor()
        self.telemetry = ControlTelemetry(np.zeros(3), np.zeros(3), np.zeros(3))
        self.contacts: ContactForces | None = None
        self._tau = np.zeros((len(JOINTS), 3))
        self._prev_ref_pos: np.ndarray | None = None

    def update(self, state: CharacterState, ref: ReferencePose, mass_matrix: np.ndarray) -> None:
        cfg = self.cfg
        m = self.mass.total_kg
        w = self._supporting(ref.stance_weight, state)
        frames = JointFrames(state)
        jac = FloatingJacobians(state, frames)
        com, com_vel = self.mass.com(state), self.mass.com_velocity(state)

        # Desired force on the body: Eq. 16 (first line) horizontally; vertically the pelvis height of Eq. 9.
        force = com_virtual_force(ref.com_world, ref.com_vel_world, com, com_vel, m, cfg.com_force_kp_npm,
                                  cfg.com_force_kd_nspm)
        # The pelvis height above the supporting ankles as they are (a loaded sole sinks into the ground's spring
        # by a centimetre or two; a target above the reach of straight legs could only be met by flailing).
        support = [s for s, ws in w.items() if ws > 0]
        ankle_z = (float(np.mean([state.link_origin_world[_FOOT_LINK[s]][2] for s in support])) if support
                   else ANKLE_HEIGHT_M)
        pelvis_z_d = ref.pelvis_world[2] - ANKLE_HEIGHT_M + ankle_z
        force[2] = m * (cfg.com_force_kp_npm * (pelvis_z_d - state.root_pos_world[2])
                        - cfg.com_force_kd_nspm * state.root_lin_vel_world[2])
        f_lipm = np.zeros(3)
        if cfg.lipm_time_sync and ref.lipm is not None:  # Eq. 21-23, bounded by Eq. 26
            f_lipm = bounded_lipm_sync_force(ref.lipm, m, self.g, cfg.lipm_force_limit_n, cfg.enforce_bounds,
                                             self.bounds, state.time_s)
            force += f_lipm
        moment = root_virtual_torque(ref.root_quat_wxyz, state.root_quat_wxyz, state.root_ang_vel_world,
                                     cfg.momentum_root_kp, cfg.momentum_root_kd, cfg.root_yaw_gain_scale)
        g_vec = np.array([0.0, 0.0, self.g])

        qd = np.concatenate([state.root_lin_vel_world, state.root_ang_vel_world,
                             flatten_joint_values(state.joint_vel)])
        # Desired joint accelerations: Eq. 13 per unit inertia.
        ref_vel = (reference_velocity(self._prev_ref_pos, ref.joint_pos, self.control_dt_s)
                   if self._prev_ref_pos is not None else np.zeros((len(JOINTS), 3)))
        self._prev_ref_pos = ref.joint_pos.copy()
        omega, zeta = cfg.joint_tracking_omega_rad_s, cfg.joint_tracking_damping_ratio
        e = joint_error(state.joint_pos, ref.joint_pos)
        qdd_joint = omega * omega * e + 2.0 * zeta * omega * (ref_vel - state.joint_vel)
        # The pelvis orientation as a task of its own (the root virtual torque's target, per unit inertia): the
        # whole-body moment above leaves it free to turn against the legs.
        e_root = rot.rotvec_from_quat(rot.multiply(ref.root_quat_wxyz, rot.conjugate(state.root_quat_wxyz)))
        alpha_root = omega * omega * e_root - 2.0 * zeta * omega * np.asarray(state.root_ang_vel_world)
        qdd_des = np.concatenate([force / m, alpha_root, flatten_joint_values(qdd_joint)])
        # Tracking errors weighed by each DOF's inertia, M_ii Δq̈_i².
        weights = cfg.joint_tracking_weight * np.diag(mass_matrix)
        weights[:3] = 0.0

        # A stance foot that does not touch yet is lowered onto the ground (a foot no force is planned for would
        # otherwise be lifted by the other's reaction): its sole is driven a little below the ground.
        task_rows, task_acc = [], []
        for s, ws in ref.stance_weight.items():
            if ws > 0 and w[s] <= 0:
                link = _FOOT_LINK[s]
                ankle = state.link_origin_world[link]
                row = jac.point_linear(link, ankle)[2]
                task_rows.append(row)
                task_acc.append(omega * omega * (ANKLE_HEIGHT_M - GROUND_PRESS_M - ankle[2]) - 2.0 * zeta * omega
                                * float(row @ qd))

        # Ground forces on the sole corners of the supporting feet (contact_forces.py) and the feet kept still.
        corners = {s: sole_corners_world(state.link_origin_world[_FOOT_LINK[s]],
                                         state.link_quat_wxyz[_FOOT_LINK[s]]) for s, ws in w.items() if ws > 0}
        contact_rows = []
        basis: np.ndarray = np.zeros((0, 6))
        wrench = np.zeros((6, 0))
        b_force = np.zeros((N_DOFS, 0))
        if corners:
            basis, wrench = wrench_basis(com, corners, self.friction)
            cols: list[np.ndarray] = []
            for s, pts in corners.items():
                link = _FOOT_LINK[s]
                for i in range(16):  # corner i // 4, pyramid edge i % 4 (contact_forces.wrench_basis)
                    cols.append(jac.point_linear(link, pts[i // 4]).T @ basis[len(cols), :3])
                contact_rows += [jac.point_linear(link, pts.mean(axis=0)), jac.angular(link)]
            b_force = np.array(cols).T
        j_c = np.vstack(contact_rows) if contact_rows else np.zeros((0, N_DOFS))
        contact_accel = -cfg.contact_velocity_gain * (j_c @ qd)
        bias = jac.mass_weighted_linear(state.link_com_world, self.mass.link_mass_kg).T @ g_vec  # gravity
        row_w = np.array([1.0, 1.0, 1.0, *(3 * [cfg.momentum_moment_weight_per_m])])
        qdd, lam = solve_with_contact_forces(
            mass_matrix, bias, b_force, j_c, contact_accel, qdd_des, weights, wrench,
            np.concatenate([force + m * g_vec, moment]), row_w, regularisation(corners, w),
            np.array(task_rows).reshape(-1, N_DOFS), np.array(task_acc), FOOT_TASK_WEIGHT)
        q_contact = b_force @ lam
        self.contacts = None
        if corners:
            f = basis[:, :3] * lam[:, None]
            achieved = wrench @ lam - np.concatenate([force + m * g_vec, moment])
            self.contacts = ContactForces(corners, {s: f[16 * i:16 * (i + 1)].reshape(4, 4, 3).sum(axis=1)
                                                    for i, s in enumerate(corners)}, achieved[:3], achieved[3:])
        tau = unflatten_joint_values(joint_torques(mass_matrix, bias, q_contact, qdd))
        tau[~_IS_BALL, 1:] = 0.0
        self._tau = np.clip(tau, -TORQUE_LIMIT, TORQUE_LIMIT)
        self.telemetry = ControlTelemetry(force, f_lipm, moment)

    @staticmethod
    def _supporting(stance_weight: dict[str, float], state: CharacterState) -> dict[str, float]:
        """The stance feet that touch the ground or are about to (a planted foot that no force is planned for
        would be lifted by the others' reaction, so a stance foot just above the ground counts as support)."""
        near = {s: state.foot_contact_force_n[f"{s}_ankle"] > CONTACT_FORCE_N for s in stance_weight}
        w = {s: v if near[s] else 0.0 for s, v in stance_weight.items()}
        total = sum(w.values())
        return {s: v / total for s, v in w.items()} if total > 0 else w

    def torques(self, fb: JointFeedback) -> Torques:
        return Torques(self._tau.copy())

"""The balance and synchronisation controller (Sec. 6) realised by contact-consistent inverse dynamics.

Same parts as controller.py, realised differently:

* COM virtual force (Eq. 16, first line, with Eq. 19 errors; per unit mass, with the gains of a capture-point
  tracking law, ControlConfig.momentum_com_kp/kd, instead of Table 3's: docs/decisions.md) plus the LIPM
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

from stylesync.config import ControlConfig
from stylesync.motion import bounds as bnd
from stylesync.control.contact_forces import (
    feasible_horizontal_force,
    regularisation,
    sole_corners_world,
    sole_touches,
    wrench_basis,
)
from stylesync.control.controller import TORQUE_LIMIT, ControllerBase, ControlTelemetry, supporting_weights
from stylesync.control.crvc import com_virtual_force, root_orientation_error, root_pd
from stylesync.control.floating_jacobian import FloatingJacobians
from stylesync.control.inverse_dynamics import joint_torques, solve_with_contact_forces
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.model_compensation import bounded_lipm_sync_force
from stylesync.control.pid import IS_BALL
from stylesync.control.stable_pd import flatten_joint_values, unflatten_joint_values
from stylesync.motion.reference import ReferencePose
from stylesync.motion.stance_fsm import swing_side
from stylesync.model.state import CharacterState, JointFeedback, MassProperties, Torques
from stylesync.model.character import ANKLE_HEIGHT_M, LINK_NAMES, N_DOFS, ROOT_DOFS

_FOOT_LINK = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
# A stance foot not yet touching is aimed this far below the ground [m], with this weight against a joint's: with
# 2 cm and 100 a landing foot bounced off and slid in double stance (docs/decisions.md, "Landing").
GROUND_PRESS_M = 0.035
FOOT_TASK_WEIGHT = 1000.0
# A joint's desired acceleration is saturated at ControlConfig.joint_acceleration_limit_rad_s2 or, where higher, at
# what this share of its torque limit gives its own inertia: the feet (0.001-0.005 kg·m²) were otherwise held to a
# fraction of a N·m, and a swing foot whipped by its leg rolled over by up to 115°.
JOINT_ACCEL_TORQUE_SHARE = 0.1
# Each DOF's tracking weight M_ii is taken as at least this [kg·m²]: with the feet's own inertia, a swing foot's
# tracking was the cheapest term to trade for the wrench, and it swung tilted by 20-100° and landed on an edge.
MIN_TRACKING_INERTIA_KGM2 = 0.05


class MomentumBalanceController(ControllerBase):
    def __init__(self, cfg: ControlConfig, mass: MassProperties, gravity_mps2: float, physics_dt_s: float,
                 control_dt_s: float, bounds: bnd.BoundsMonitor | None = None, friction: float = 0.9):
        super().__init__(cfg, mass, gravity_mps2, physics_dt_s, control_dt_s, bounds, friction)
        self._tau = Torques.zeros()  # held from one control tick to the next [N·m]
        self._g_vec = np.array([0.0, 0.0, gravity_mps2])
        # Weights of the wrench rows (force, moment) in the plan (inverse_dynamics.solve_with_contact_forces).
        self._wrench_row_weights = np.array([1.0, 1.0, 1.0, *(3 * [cfg.momentum_moment_weight_per_m])])
        self._free_lam: np.ndarray | None = None  # which ground forces were positive at the last tick
        self._free_lam_feet: tuple[str, ...] = ()  # for these supporting feet

    def update(self, state: CharacterState, ref: ReferencePose, mass_matrix: np.ndarray) -> None:
        cfg = self.cfg
        m = self.mass.total_kg
        touching = {s: sole_touches(state.link_origin_world[_FOOT_LINK[s]], state.link_quat_wxyz[_FOOT_LINK[s]], p,
                                    cfg.sole_contact_gap_m) for s, p in state.feet_pressing().items()}
        w = supporting_weights(ref.stance_weight, touching)
        frames = JointFrames(state)
        jac = FloatingJacobians(state, frames)
        com, com_vel = self.mass.com(state), self.mass.com_velocity(state)

        # Desired force on the body: Eq. 16 (first line) horizontally; vertically the pelvis height of Eq. 9.
        force = com_virtual_force(ref.com_world, ref.com_vel_world, com, com_vel, m, cfg.momentum_com_kp,
                                  cfg.momentum_com_kd)
        # The pelvis height above the supporting ankles as they are (a loaded sole sinks into the ground's spring
        # by a centimetre or two; a target above the reach of straight legs could only be met by flailing).
        support = [s for s, ws in w.items() if ws > 0]
        ankle_z = (sum(float(state.link_origin_world[_FOOT_LINK[s], 2]) for s in support) / len(support) if support
                   else ANKLE_HEIGHT_M)
        pelvis_z_d = ref.pelvis_world[2] - ANKLE_HEIGHT_M + ankle_z
        force[2] = m * (cfg.momentum_com_kp * (pelvis_z_d - state.root_pos_world[2])
                        - cfg.momentum_com_kd * state.root_lin_vel_world[2])
        f_lipm = np.zeros(3)
        if cfg.lipm_time_sync and ref.lipm is not None:  # Eq. 21-23, bounded by Eq. 26
            f_lipm = bounded_lipm_sync_force(ref.lipm, m, self.g, cfg.lipm_force_limit_n, cfg.enforce_bounds,
                                             self.bounds, state.time_s)
            force += f_lipm
        e_root = root_orientation_error(ref.root_quat_wxyz, state.root_quat_wxyz)  # for the moment and the task
        moment = root_pd(e_root, state.root_ang_vel_world, cfg.momentum_root_kp, cfg.momentum_root_kd,
                         cfg.root_yaw_gain_scale)

        qd = np.concatenate([state.root_lin_vel_world, state.root_ang_vel_world,
                             flatten_joint_values(state.joint_vel)])
        # Desired joint accelerations: Eq. 13 per unit inertia.
        omega, zeta = cfg.joint_tracking_omega_rad_s, cfg.joint_tracking_damping_ratio
        kp, kd = omega * omega, 2.0 * zeta * omega
        e = self._error_and_reference_velocity(state.joint_pos, ref)
        qdd_joint = kp * e + kd * (self._ref_vel - state.joint_vel)
        # Saturated: a jump of the reference (a stance change, a landing) would otherwise ask for accelerations
        # whose torques exceed the joints' limits, and the clipped torques no longer realise the planned forces.
        m_diag = mass_matrix.diagonal()
        own = JOINT_ACCEL_TORQUE_SHARE * TORQUE_LIMIT / np.maximum(unflatten_joint_values(m_diag[ROOT_DOFS:]), 1e-6)
        lim = np.maximum(cfg.joint_acceleration_limit_rad_s2, own)
        qdd_joint = np.minimum(np.maximum(qdd_joint, -lim), lim)  # np.clip's checks cost more than this
        # The pelvis orientation as a task of its own (the root virtual torque's PD law, per unit inertia): the
        # whole-body moment above leaves it free to turn against the legs. The root's linear acceleration has no
        # target (weight 0): the ground forces decide it.
        alpha_root = root_pd(e_root, state.root_ang_vel_world, kp, kd, yaw_scale=1.0)
        qdd_des = np.concatenate([np.zeros(3), alpha_root, flatten_joint_values(qdd_joint)])
        # Tracking errors weighed by each DOF's inertia, M_ii Δq̈_i².
        weights = cfg.joint_tracking_weight * np.maximum(m_diag, MIN_TRACKING_INERTIA_KGM2)
        weights[:3] = 0.0

        # A stance foot that does not touch yet is lowered onto the ground (a foot no force is planned for would
        # otherwise be lifted by the other's reaction), and so is a swing foot the reference is held for (a late
        # contact, Sec. 5.1): its sole is driven a little below the ground.
        task_rows, task_acc = [], []
        swing = swing_side(ref.character_stance)
        for s, ws in ref.stance_weight.items():
            if (ws > 0 and w[s] <= 0) or (ref.held and s == swing):
                link = _FOOT_LINK[s]
                ankle = state.link_origin_world[link]
                row = jac.point_linear(link, ankle)[2]
                task_rows.append(row)
                task_acc.append(kp * (ANKLE_HEIGHT_M - GROUND_PRESS_M - ankle[2]) - kd * float(row @ qd))

        # Ground forces on the sole corners of the supporting feet (contact_forces.py) and the feet kept still.
        corners = {s: sole_corners_world(state.link_origin_world[_FOOT_LINK[s]],
                                         state.link_quat_wxyz[_FOOT_LINK[s]]) for s, ws in w.items() if ws > 0}
        contact_rows = []
        wrench = np.zeros((6, 0))
        b_force = np.zeros((N_DOFS, 0))
        force = feasible_horizontal_force(force, com, corners, m, self.g)
        if corners:
            edges, wrench = wrench_basis(com, corners, self.friction)
            cols = []
            for side, pts in corners.items():
                link = _FOOT_LINK[side]
                j_pts = jac.points_linear(link, pts)  # (4, 3, N_DOFS)
                # B's columns: J(p_c)^T β_e, corner by corner, edge by edge (contact_forces.wrench_basis's order)
                cols.append((edges @ j_pts).transpose(2, 0, 1).reshape(N_DOFS, -1))
                # The sole centre's Jacobian: the mean of the 4 corners' (a point's Jacobian is affine in the point).
                contact_rows += [0.25 * j_pts.sum(axis=0), jac.angular(link)]
            b_force = np.hstack(cols)
        j_c = np.vstack(contact_rows) if contact_rows else np.zeros((0, N_DOFS))
        contact_accel = -cfg.contact_velocity_gain * (j_c @ qd)
        bias = jac.gravity_force(state.link_com_world, self.mass.link_mass_kg, self.g)  # gravity
        feet = tuple(corners)
        qdd, lam, free = solve_with_contact_forces(
            mass_matrix, bias, b_force, j_c, contact_accel, qdd_des, weights, wrench,
            np.concatenate([force + m * self._g_vec, moment]), self._wrench_row_weights, regularisation(corners, w),
            np.array(task_rows).reshape(-1, N_DOFS), np.array(task_acc), FOOT_TASK_WEIGHT,
            self._free_lam if feet == self._free_lam_feet else None)
        self._free_lam, self._free_lam_feet = free, feet  # the warm start of the next tick's force plan
        tau = unflatten_joint_values(joint_torques(mass_matrix, bias, b_force @ lam, qdd))
        tau[~IS_BALL, 1:] = 0.0
        self._tau = Torques(np.minimum(np.maximum(tau, -TORQUE_LIMIT), TORQUE_LIMIT))
        self.telemetry = ControlTelemetry(force, f_lipm, moment)

    needs_joint_feedback = False

    def torques(self, fb: JointFeedback | None) -> Torques:
        return self._tau

"""The balance and synchronisation controller (Sec. 6) as whole-body control: tasks, contacts, one QP per tick.

The same parts as the paper's controller (controller.py), composed as tasks of one quadratic programme
(formulation.py, solved by DAQP in solver.py):

* joint posture (Eq. 13 per DOF as a desired acceleration, ``q̈* = ω² e + 2 ζ ω ė``): the retargeted operator pose;
* pelvis orientation (the root virtual torque's PD law, per unit inertia);
* centroidal momentum: the COM virtual force of Eq. 16 (first line, Eq. 19 errors; gains of a capture-point
  tracking law, ControlConfig.momentum_com_kp/kd, docs/decisions.md), the pelvis height of Eq. 9 vertically, the
  LIPM time-sync force (Eq. 21-23, bounded by Eq. 26), and the root virtual torque (Eq. 16, second line) less a
  damping of the whole body's angular momentum about its COM (WholeBodyConfig.angular_momentum_damping_1ps);
* a stance foot that has not touched down yet (or a swing foot held for a late contact, Sec. 5.1) pressed onto the
  ground; the swing ankle of a recovery step (motion/recovery_step.py) following its target in world space;
  optionally the hands following the operator's hands (ControlConfig.hand_tasks);
* sole contacts (contacts.py): the ground forces the soles can pass, found with the accelerations, replace the
  Jacobian-transpose mapping of Eq. 17-18 and the IPM ankle torque of Eq. 20 (a centre of pressure is placed,
  not implied); gravity compensation (Eq. 14-15) is in the equations of motion, with the feet's reactions.

Why not Eq. 17-18 alone: they assume a static body and feet that push as asked. Measured with that mapping, the
standing character toppled when it waved its arms and the walk fell within a second of its first step
(docs/decisions.md). Adding a task is one class in ``tasks/`` and one ``add_task`` line in ``__init__``.

A QP with no feasible point (a supporting leg stretched to its knee's limit can close a chain whose contact rows ask
for more than the limits allow) is solved again with its torque and hinge limits opened
(``WholeBodyFormulation.with_limits_opened``, WholeBodyConfig.relax_limits_when_infeasible): the torques are clipped
to their limits as always, and the failed solve's last iterate is not applied.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ControlConfig
from stylesync.control.contacts import MIN_WEIGHT, SoleContact, feasible_horizontal_force, sole_touches
from stylesync.control.controller import TORQUE_LIMIT, ControllerBase, ControlTelemetry, supporting_weights
from stylesync.control.crvc import com_virtual_force, root_orientation_error, root_pd
from stylesync.control.formulation import QpProblem, WholeBodyFormulation, hinge_limits
from stylesync.control.gravity_compensation import LEG_JOINTS
from stylesync.control.joint_speed_limit import limit_joint_speed
from stylesync.control.model_compensation import bounded_lipm_sync_force
from stylesync.control.own_step_push import own_step_push_bound
from stylesync.control.pid import IS_BALL
from stylesync.control.sole_wrench_contact import SoleWrenchContact
from stylesync.control.solver import DaqpSolver
from stylesync.control.stable_pd import flatten_joint_values, unflatten_joint_values
from stylesync.control.tasks import CentroidalMomentumTask, FrameOrientationTask, FramePositionTask, JointPostureTask
from stylesync.control.toe_contact import ToeContact, toe_off_sides
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    JOINT_DOF_COUNT,
    JOINT_DOF_START,
    LINK_NAMES,
    N_JOINT_DOFS,
    Q_WORLD_MODEL,
    ROOT_DOFS,
    SHANK_LENGTH_M,
    SIDES,
    THIGH_LENGTH_M,
)
from stylesync.model.character_model import HAND_FRAMES, CharacterModel
from stylesync.model.state import CharacterState, JointFeedback, MassProperties, Torques
from stylesync.motion import bounds as bnd
from stylesync.motion.reference import ReferencePose
from stylesync.motion.stance_fsm import Stance, swing_side

log = logging.getLogger("stylesync.control")
_FOOT_LINK = {s: LINK_NAMES.index(f"{s}_ankle") for s in SIDES}
_HIP_LINK = {s: LINK_NAMES.index(f"{s}_hip") for s in SIDES}
_LEG_LENGTH_M = THIGH_LENGTH_M + SHANK_LENGTH_M  # hip to ankle, straight [m]
# Each leg's hip, knee and ankle DOFs, in the joint-DOF layout of the posture task.
_LEG_DOFS = {s: np.concatenate([JOINT_DOF_START[k] + np.arange(JOINT_DOF_COUNT[k]) for k in LEG_JOINTS[s]])
             for s in SIDES}


def _leg_share(support: tuple[str, ...], share: float) -> np.ndarray:
    """(n_joint_dofs,) the posture task's weight factor: ``share`` on the supporting legs' DOFs, 1 elsewhere."""
    out = np.ones(N_JOINT_DOFS)
    for s in support:
        out[_LEG_DOFS[s]] = share
    return out


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
# A recovery step's target this far or further below the foot's height on the ground means its landing is due: the
# motion stage aims the foot below the ground once the swing's touchdown share is over (recovery_step.swing_target) [m]
LANDING_DUE_BELOW_M = 0.005
# The hinges' limits are kept over this horizon: q + q̇ T + ½ q̈ T² stays within them [s].
JOINT_LIMIT_HORIZON_S = 0.05
# A hand target is kept within this share of the arm's length from its shoulder (a straight arm reaches it).
HAND_REACH_SHARE = 1.0
_TORQUE_LIMIT_FLAT = flatten_joint_values(np.repeat(TORQUE_LIMIT, 3, axis=1))


@dataclass(frozen=True)
class PlanAttribution:
    """WholeBodyController.plan_attribution: the ground force the last QP plans [N], as solved (key "") and with each
    task switched off (key: its name), and the posture task's per-DOF cost, desired and planned joint accelerations
    (n_joint_dofs,) in the solution as solved [-, rad/s², rad/s²]."""

    ground_force_n: dict[str, np.ndarray]
    posture_cost: np.ndarray
    posture_desired_rad_s2: np.ndarray
    posture_planned_rad_s2: np.ndarray


def recovery_landing_due(target_world: np.ndarray) -> bool:
    """Whether a recovery step's ankle target (3,) [m] is below the ground, i.e. its landing is due."""
    return bool(target_world[2] < ANKLE_HEIGHT_M - LANDING_DUE_BELOW_M)


class WholeBodyController(ControllerBase):
    needs_joint_feedback = False

    def __init__(self, cfg: ControlConfig, model: CharacterModel, mass: MassProperties, gravity_mps2: float,
                 physics_dt_s: float, control_dt_s: float, bounds: bnd.BoundsMonitor | None = None,
                 friction: float = 0.9):
        super().__init__(cfg, mass, gravity_mps2, physics_dt_s, control_dt_s, bounds, friction)
        self.wb = wb = cfg.whole_body
        self.model = model
        self._tau = Torques.zeros()  # held from one control tick to the next [N·m]
        self.relaxed_solves = 0  # QPs with no feasible point solved again with their limits opened
        omega, zeta = wb.joint_tracking_omega_rad_s, wb.joint_tracking_damping_ratio
        self.kp, self.kd = omega * omega, 2.0 * zeta * omega
        self.formulation = WholeBodyFormulation(_TORQUE_LIMIT_FLAT, hinge_limits(model.joint_limits_rad),
                                                wb.contact_velocity_gain, JOINT_LIMIT_HORIZON_S)
        f = self.formulation
        self.posture = f.add_task(JointPostureTask(wb.joint_tracking_weight, MIN_TRACKING_INERTIA_KGM2))
        self.pelvis = f.add_task(FrameOrientationTask("pelvis_orientation", "root", self.kp, self.kd, 0.0,
                                                      rot.conjugate(Q_WORLD_MODEL)))
        self.momentum = f.add_task(CentroidalMomentumTask(1.0, wb.momentum_moment_weight_per_m ** 2))
        self.foot_press = {s: f.add_task(FramePositionTask(f"{s}_foot_press", f"{s}_ankle", self.kp, self.kd,
                                                           FOOT_TASK_WEIGHT, axes=(2,))) for s in SIDES}
        for task in self.foot_press.values():
            task.target_world = np.array([0.0, 0.0, ANKLE_HEIGHT_M - GROUND_PRESS_M])
        self.foot_hold = ({s: f.add_task(FramePositionTask(f"{s}_foot_hold", f"{s}_ankle", self.kp, self.kd,
                                                           FOOT_TASK_WEIGHT, axes=(0, 1))) for s in SIDES}
                          if wb.press_holds_foot else {})
        for task in self.foot_hold.values():
            task.active = False  # until a stance foot comes off the ground (update)
        self.hands = ({s: f.add_task(FramePositionTask(f"{s}_hand", HAND_FRAMES[s], wb.hand_task_kp,
                                                       wb.hand_task_kd, wb.hand_task_weight)) for s in SIDES}
                      if wb.hand_tasks else {})
        # The swing ankle of the character's own step follows its target (weight 0: no task)
        self.recovery_feet = ({s: f.add_task(FramePositionTask(f"{s}_recovery_foot", f"{s}_ankle",
                                                               wb.recovery_foot_task_kp, wb.recovery_foot_task_kd,
                                                               wb.recovery_foot_task_weight)) for s in SIDES}
                              if wb.recovery_foot_task_weight > 0 else {})
        self._recovery_target: dict[str, np.ndarray] = {}  # the last tick's recovery-step ankle targets [m]
        self._arm_length_m = model.rest_distance("left_shoulder", "left_elbow") + model.rest_distance(
            "left_elbow", "left_wrist")
        self._hand_target: dict[str, np.ndarray] = {}  # the last tick's hand targets [m]
        # The posture task's per-DOF weight share for each set of supporting feet (stance_leg_tracking_share)
        self._leg_share: dict[tuple[str, ...], np.ndarray] = {support: _leg_share(support, wb.stance_leg_tracking_share)
                           for support in ((), ("left",), ("right",), ("left", "right"))}
        contact = SoleWrenchContact if wb.sole_wrench_cone else SoleContact
        self.contacts = {s: contact(s, friction, mass.total_kg * gravity_mps2) for s in SIDES}
        # A rear sole on its toes (WholeBodyConfig.toe_off_leg_stretch)
        self.toe_contacts = {s: ToeContact(s, friction, mass.total_kg * gravity_mps2) for s in SIDES}
        self.on_toes: set[str] = set()  # the supporting feet on their toes this tick
        self.solver = DaqpSolver()
        # What the last tick's QP was built from, its soles, bounds and problem (plan_attribution)
        self._last_qp: tuple[list, list, QpProblem] | None = None

    def update(self, state: CharacterState, ref: ReferencePose) -> None:
        cfg, wb = self.cfg, self.wb
        model = self.model
        model.update(state)
        m = self.mass.total_kg
        touching = {s: sole_touches(state.link_origin_world[_FOOT_LINK[s]], state.link_quat_wxyz[_FOOT_LINK[s]], p,
                                    wb.sole_contact_gap_m) for s, p in state.feet_pressing().items()}
        w = supporting_weights(ref.stance_weight, touching)
        if (wb.standing_sole_min_load_share > 0.0 and ref.both_stand_still and ref.character_stance is Stance.DS
                and all(touching.values())):
            # Where both stand still both soles on the ground stay contacts, even with his weight (and the COM
            # target) over one foot: a sole of no stance weight left the QP's contacts while it bore 50 N, was free
            # to the tasks and slid (standing_sole_min_load_share)
            w = {s: min(max(v, MIN_WEIGHT), 1.0 - MIN_WEIGHT) for s, v in w.items()}
        com, com_vel = model.com_world, model.com_vel_world

        # Centroidal momentum rate: Eq. 16 (first line) horizontally; vertically the pelvis height of Eq. 9.
        force = com_virtual_force(ref.com_world, ref.com_vel_world, com, com_vel, m, wb.momentum_com_kp,
                                  wb.momentum_com_kd)
        # The pelvis height above the supporting ankles as they are (a loaded sole sinks into the ground's spring
        # by a centimetre or two; a target above the reach of straight legs could only be met by flailing).
        support = [s for s, ws in w.items() if ws > 0]
        ankle_z = (sum(float(state.link_origin_world[_FOOT_LINK[s], 2]) for s in support) / len(support) if support
                   else ANKLE_HEIGHT_M)
        pelvis_z_d = ref.pelvis_world[2] - ANKLE_HEIGHT_M + ankle_z
        # The target's rise on both feet, shared (WholeBodyConfig.pelvis_rate_share); its descent is left to the
        # regulator, and so is the rise over one foot (a gait's vault over its stance leg)
        pelvis_vz_d = wb.pelvis_rate_share * max(ref.pelvis_vel_z_mps, 0.0) if len(support) == 2 else 0.0
        kp_z, kd_z = wb.momentum_com_kp, wb.momentum_com_kd
        if (wb.landing_pelvis_gains is not None and ref.recovery_ankle_world is not None
                and state.root_pos_world[2] > pelvis_z_d
                and any(recovery_landing_due(t) for t in ref.recovery_ankle_world.values())):
            kp_z, kd_z = wb.landing_pelvis_gains  # an own step's landing: the pelvis brought down in its time
        force[2] = m * (kp_z * (pelvis_z_d - state.root_pos_world[2])
                        + kd_z * (pelvis_vz_d - state.root_lin_vel_world[2]))
        f_lipm = np.zeros(3)
        if cfg.lipm_time_sync and ref.lipm is not None:  # Eq. 21-23, bounded by Eq. 26
            f_lipm = bounded_lipm_sync_force(ref.lipm, m, self.g, cfg.lipm_force_limit_n, cfg.enforce_bounds,
                                             self.bounds, state.time_s)
            force += f_lipm
        self.on_toes = (self._toe_off(state, support, com) if ref.his_way_speed_mps >= wb.toe_off_min_way_speed_mps
                        else set())
        contacts = [self.toe_contacts[s] if s in self.on_toes else self.contacts[s] for s in support]
        for c in contacts:
            c.stance_weight = w[c.side]
            # Both soles loaded where he stands still (WholeBodyConfig.standing_sole_min_load_share)
            c.min_load_share = wb.standing_sole_min_load_share if len(contacts) == 2 and ref.both_stand_still else 0.0
            c.update(model)  # its corners bound the force here; the formulation reads the rest of it
        force = feasible_horizontal_force(force, com, [c.corners_world for c in contacts], m, self.g)
        e_root = root_orientation_error(ref.root_quat_wxyz, state.root_quat_wxyz)
        moment = root_pd(e_root, state.root_ang_vel_world, wb.momentum_root_kp, wb.momentum_root_kd,
                         cfg.root_yaw_gain_scale)
        if wb.angular_momentum_damping_1ps > 0.0:  # the body's angular momentum about its COM damped (config.py)
            moment = moment - wb.angular_momentum_damping_1ps * model.centroidal_angular_momentum
        self.momentum.force_n, self.momentum.moment_nm = force, moment

        # Joint posture: Eq. 13 per unit inertia, saturated (a jump of the reference, a stance change or a landing,
        # would otherwise ask for accelerations whose torques exceed the joints' limits).
        e = self._error_and_reference_velocity(state.joint_pos, ref)
        qdd_joint = flatten_joint_values(self.kp * e + self.kd * (self._ref_vel - state.joint_vel))
        m_diag = model.mass_matrix.diagonal()
        own = JOINT_ACCEL_TORQUE_SHARE * _TORQUE_LIMIT_FLAT / np.maximum(m_diag[ROOT_DOFS:], 1e-6)
        lim = np.maximum(wb.joint_acceleration_limit_rad_s2, own)
        self.posture.desired_accel = np.minimum(np.maximum(qdd_joint, -lim), lim)

        # Pelvis orientation, weighted by the pelvis's rotational inertia about world axes (as a joint's by M_ii); on
        # one foot by single_stance_pelvis_share of that, so that the swing leg's turn of the pelvis does not hold
        # the swing back (WholeBodyConfig).
        r_base = model.data.oMi[1].rotation
        m_rot_world = r_base @ model.mass_matrix[3:6, 3:6] @ r_base.T
        self.pelvis.weight = wb.joint_tracking_weight * np.maximum(m_rot_world.diagonal(), MIN_TRACKING_INERTIA_KGM2)
        if len(support) == 1:
            self.pelvis.weight = self.pelvis.weight * wb.single_stance_pelvis_share
        self.pelvis.target_quat_wxyz = ref.root_quat_wxyz

        # A stance foot that does not touch yet is lowered onto the ground (a foot no force is planned for would
        # otherwise be lifted by the other's reaction), and so is a swing foot the reference is held for.
        swing = swing_side(ref.character_stance)
        for s, task in self.foot_press.items():
            # A stance foot off the ground; in the character's double stance (press_double_stance_feet) either foot
            # off it, whatever its stance weight
            lifted = w[s] <= 0 and (ref.stance_weight[s] > 0 or (wb.press_double_stance_feet and swing is None))
            task.active = lifted or (ref.press_swing_foot and s == swing)
            hold = self.foot_hold.get(s)
            if hold is not None:  # ... is held where it came off (press_holds_foot)
                if lifted and not hold.active:
                    hold.target_world = state.link_origin_world[_FOOT_LINK[s]].copy()
                hold.active = lifted
        for s, task in self.recovery_feet.items():
            target = None if ref.recovery_ankle_world is None else ref.recovery_ankle_world.get(s)
            task.active = target is not None
            if target is None:
                self._recovery_target.pop(s, None)
                continue
            self._move_target(task, self._recovery_target, s, target, np.zeros(3))  # at rest on the step's first tick
            if wb.recovery_foot_target_rate == "profile" and ref.recovery_ankle_vel_world is not None:
                task.target_vel_world = ref.recovery_ankle_vel_world[s]  # the swing profile's, not the re-planning's
            # A target below the ground: the landing is due and the foot has not touched (the step ends when it does)
            due = recovery_landing_due(target)
            task.weight = wb.recovery_foot_landing_weight if due else wb.recovery_foot_task_weight
        for s, task in self.hands.items():
            task.active = ref.hand_world is not None
            if ref.hand_world is not None:
                # Within the character's reach from its shoulder (the operator's arms, scaled by his legs, may
                # reach further); the target's velocity from successive ticks.
                shoulder = model.frame_position(model.frame_id(f"{s}_shoulder"))
                offset = ref.hand_world[s] - shoulder
                dist = float(np.linalg.norm(offset))
                reach = HAND_REACH_SHARE * self._arm_length_m
                target = shoulder + offset * min(1.0, reach / max(dist, 1e-9))
                self._move_target(task, self._hand_target, s, target, state.root_lin_vel_world)

        # The supporting legs' posture weighs stance_leg_tracking_share of the rest's (WholeBodyConfig): their joint
        # angles are where the pelvis is over the feet, which the momentum and pelvis tasks already ask for.
        self.posture.dof_scale = self._leg_share[tuple(support)]
        # The push of a step of the character's own, on one sole, bounded (WholeBodyConfig.own_step_push_bound)
        bounded = {"off": False, "he_stands": ref.recovery_while_he_stands,
                   "always": ref.recovery_ankle_world is not None}[wb.own_step_push_bound]
        bounds = ([own_step_push_bound(model, contacts[0].corners_world, m, self.g)]
                  if bounded and len(contacts) == 1 else [])
        problem = self.formulation.build(model, contacts, bounds)
        self._last_qp = (contacts, bounds, problem)
        result = self.solver.solve(problem)
        if not result.solved and self.wb.relax_limits_when_infeasible:
            failed = result.exitflag
            result = self.solver.solve(self.formulation.with_limits_opened(problem))
            self.relaxed_solves += 1
            log.info("t=%.2f s: the whole-body QP found no optimum (DAQP exit %d); solved again with the torque and "
                     "hinge limits opened (exit %d)", state.time_s, failed, result.exitflag)
        if not result.solved:
            log.warning("t=%.2f s: the whole-body QP found no optimum (DAQP exit %d); its last iterate is used",
                        state.time_s, result.exitflag)
        tau = unflatten_joint_values(self.formulation.torques(model, problem, result.x))
        tau[~IS_BALL, 1:] = 0.0
        if wb.joint_speed_limit_rad_s is not None:  # the joints' no-load speed
            limit_joint_speed(tau, state.joint_vel, wb.joint_speed_limit_rad_s)
        self._tau = Torques(np.minimum(np.maximum(tau, -TORQUE_LIMIT), TORQUE_LIMIT))
        self.telemetry = ControlTelemetry(force, f_lipm, moment)

    def plan_attribution(self) -> PlanAttribution:
        """What each task of the last tick's QP does to the ground force it plans: the QP solved again (by a solver
        of its own, so that the run's warm starts stay as they are) as it was, and with each active task switched off
        in turn, each solution's total ground force (3,) [N] (the rate of the linear momentum, Ȧ_g v + A_g q̈, plus
        the body's weight), keyed by the task's name; and the joint posture task's cost per DOF in the solution as it
        was. A tool for explaining where a planned force comes from (benchmarks/qp_attribution.py)."""
        if self._last_qp is None:
            raise RuntimeError("plan_attribution needs a control tick first")
        contacts, bounds, problem = self._last_qp
        solver, model, f = DaqpSolver(), self.model, self.formulation
        weight = np.array([0.0, 0.0, self.mass.total_kg * self.g])

        def ground_force(x: np.ndarray) -> np.ndarray:
            return model.centroidal_map[:3] @ x[:ROOT_DOFS + N_JOINT_DOFS] + model.centroidal_map_dot_v[:3] + weight

        x = solver.solve(problem).x
        forces = {"": ground_force(x)}
        for task in f.tasks:
            if not task.active:
                continue
            task.active = False
            try:
                forces[task.name] = ground_force(solver.solve(f.build(model, contacts, bounds)).x)
            finally:
                task.active = True
        rows = self.posture.rows(model)
        cost = 0.5 * rows.weight * (x[ROOT_DOFS:ROOT_DOFS + N_JOINT_DOFS] - rows.target) ** 2
        return PlanAttribution(forces, cost, rows.target.copy(), x[ROOT_DOFS:ROOT_DOFS + N_JOINT_DOFS].copy())

    def _toe_off(self, state: CharacterState, support: list[str], com_world: np.ndarray) -> set[str]:
        """The supporting feet that stand on their toes this tick (toe_contact.toe_off_sides)."""
        share = self.wb.toe_off_leg_stretch
        if len(support) != 2 or share is None:
            return set()
        link, quat = state.link_origin_world, state.link_quat_wxyz
        stretch = {s: float(np.linalg.norm(link[_HIP_LINK[s]] - link[_FOOT_LINK[s]])) / _LEG_LENGTH_M
                   for s in support}
        return toe_off_sides(support, stretch, com_world, {s: link[_FOOT_LINK[s]] for s in support},
                             {s: quat[_FOOT_LINK[s]] for s in support}, share)

    def _move_target(self, task: FramePositionTask, last: dict[str, np.ndarray], side: str, target: np.ndarray,
                     first_vel_world: np.ndarray) -> None:
        """Set a frame task's target [m] and its velocity from the last tick's (``last[side]``, then updated) [m/s];
        ``first_vel_world`` when there is none."""
        previous = last.get(side)
        task.target_vel_world = (target - previous) / self.control_dt_s if previous is not None else first_vel_world
        task.target_world = last[side] = target

    def torques(self, fb: JointFeedback | None) -> Torques:
        return self._tau

    def reset(self) -> None:
        self.solver.reset()

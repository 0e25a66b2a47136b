"""The body balance and synchronisation controller (Sec. 6, Fig. 8): Eq. 18 put together.

Two rates. At each control tick (133 Hz) :meth:`update` takes the reference pose and the full state and computes
the slowly varying parts: gravity compensation (Eq. 14-15), the COM virtual force through the stance legs
(Eq. 16-17) with the LIPM time-sync force (Eq. 21-23) bounded by Eq. 25-27, and the IPM ankle torque (Eq. 20).
At each physics step (600 Hz) :meth:`torques` adds the PID (Eq. 13, "for each joint DOF at each timestep of
simulation", Sec. 6.1) and the root virtual torque on the stance hips (Eq. 16, 18), whose damping would not be
stable if held for 4.5 physics steps, then clamps to the joint torque limits.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ControlConfig
from stylesync.control.crvc import (
    HIP_JOINT,
    com_virtual_force,
    root_gain_scale,
    root_virtual_torque,
    stance_force_moments,
    stance_hip_map,
)
from stylesync.control.gravity_compensation import ANKLE_JOINT, gravity_torques
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.model_compensation import bounded_lipm_sync_force, ipm_ankle_moments
from stylesync.control.pid import IS_BALL, JointPid, joint_error, reference_velocity
from stylesync.control.stable_pd import (
    flatten_joint_values,
    implicit_gain,
    joint_damping,
    unflatten_joint_values,
)
from stylesync.control.support import limit_ankle_moment
from stylesync.model.character import JOINT_DOF_START, JOINTS, N_DOFS, Q_WORLD_MODEL, ROOT_DOFS
from stylesync.model.character_model import CharacterModel
from stylesync.model.state import CharacterState, JointFeedback, MassProperties, Torques
from stylesync.motion import bounds as bnd
from stylesync.motion.reference import ReferencePose
from stylesync.motion.stance_fsm import Stance

TORQUE_LIMIT = np.array([j.torque_limit_nm for j in JOINTS])[:, None]
PELVIS_CHILDREN = tuple(k for k, j in enumerate(JOINTS) if j.parent == "root")  # chest and both hips


@dataclass
class ControlTelemetry:
    com_force_n: np.ndarray
    lipm_force_n: np.ndarray
    root_torque_nm: np.ndarray


def supporting_weights(stance_weight: dict[str, float], touching: dict[str, bool]) -> dict[str, float]:
    """The stance weights of the feet that actually touch the ground, renormalised. Support torques (gravity
    reaction, COM force, IPM ankle torque, root torque) sent to a foot in the air would only spin it."""
    w = {s: v if touching[s] else 0.0 for s, v in stance_weight.items()}
    total = sum(w.values())
    return {s: v / total for s, v in w.items()} if total > 0 else w


class ControllerBase(ABC):
    """What every realisation of the Sec. 6 controller shares: its configuration, the character's mass, the
    movement-bounds monitor, telemetry, and the reference's joint velocity (from successive control ticks).

    ``update`` runs at each control tick, ``torques`` at each physics step, ``reset`` when the character is stood
    up again."""

    def __init__(self, cfg: ControlConfig, mass: MassProperties, gravity_mps2: float, physics_dt_s: float,
                 control_dt_s: float, bounds: bnd.BoundsMonitor | None = None, friction: float = 0.9):
        self.cfg = cfg
        self.mass = mass
        self.g = gravity_mps2
        self.friction = friction
        self.physics_dt_s = physics_dt_s
        self.control_dt_s = control_dt_s
        self.bounds = bounds if bounds is not None else bnd.BoundsMonitor()
        self.telemetry = ControlTelemetry(np.zeros(3), np.zeros(3), np.zeros(3))
        self._prev_ref_pos: np.ndarray | None = None
        self._ref_vel = np.zeros((len(JOINTS), 3))

    @abstractmethod
    def update(self, state: CharacterState, ref: ReferencePose) -> None:
        """One control tick: read the state and the reference, prepare the torques."""

    # Whether ``torques`` reads the joints' state at each physics step; a controller that holds its torques from
    # one control tick to the next does not, and the joint state is then not read between ticks.
    needs_joint_feedback = True

    @abstractmethod
    def torques(self, fb: JointFeedback | None) -> Torques:
        """The joint torques for this physics step [N·m]; ``fb`` is None unless ``needs_joint_feedback``."""

    def reset(self) -> None:  # noqa: B027 (an optional hook: controllers without accumulated state keep it)
        """Forget accumulated state (integral terms) when the character is stood up again."""

    def _error_and_reference_velocity(self, q_current: np.ndarray, ref: ReferencePose) -> np.ndarray:
        """The joint error of ``q_current`` to the reference (pid.joint_error), with the reference velocity updated
        as :meth:`_update_reference_velocity` does: both in one batched evaluation."""
        if self._prev_ref_pos is None:
            self._prev_ref_pos = ref.joint_pos.copy()
            return joint_error(q_current, ref.joint_pos)
        both = joint_error(np.array([q_current, self._prev_ref_pos]), np.array([ref.joint_pos, ref.joint_pos]))
        self._ref_vel = both[1] / self.control_dt_s  # pid.reference_velocity
        self._prev_ref_pos = ref.joint_pos.copy()
        return both[0]

    def _update_reference_velocity(self, ref: ReferencePose) -> None:
        """The reference's joint velocity for the derivative terms, from successive references at the control
        rate (zero until there are two)."""
        if self._prev_ref_pos is not None:
            self._ref_vel = reference_velocity(self._prev_ref_pos, ref.joint_pos, self.control_dt_s)
        self._prev_ref_pos = ref.joint_pos.copy()


class BalanceController(ControllerBase):
    def __init__(self, cfg: ControlConfig, model: CharacterModel, mass: MassProperties, gravity_mps2: float,
                 physics_dt_s: float, control_dt_s: float, bounds: bnd.BoundsMonitor | None = None,
                 friction: float = 0.9):
        super().__init__(cfg, mass, gravity_mps2, physics_dt_s, control_dt_s, bounds, friction)
        self.model = model
        self.jt = jt = cfg.jacobian_transpose
        self.pid = JointPid(jt, physics_dt_s)
        self._ff = np.zeros((len(JOINTS), 3))
        self._ref: ReferencePose | None = None
        self.root_kp, self.root_kd = jt.root_torque_kp, jt.root_torque_kd
        # D of stable_pd.py: the joints' diagonal is constant; the root torque's block is filled per tick.
        self._damping = joint_damping(self.pid.kp, self.pid.kd, physics_dt_s)
        self._gain = np.eye(N_DOFS - ROOT_DOFS)  # G of stable_pd, joint rows and columns
        self._root_map = np.zeros((N_DOFS - ROOT_DOFS, 3))  # S: world root torque -> stance-hip DOF torques
        self._torso_hip: int | None = None  # the stance hip that carries the root torque explicitly (see torques)
        self._torso_dofs = np.zeros(0, dtype=int)  # its DOF rows in the joint layout

    def _prepare_implicit(self, state: CharacterState, stance_weight: dict[str, float],
                          mass_matrix: np.ndarray) -> None:
        """G = I - D (M + D)^-1 for this tick (stable_pd.py), with the root torque's feedback in D."""
        dt = self.physics_dt_s
        d = self._damping.copy()
        s_map = np.zeros((N_DOFS - ROOT_DOFS, 3))
        single = [side for side, ws in stance_weight.items() if ws >= 1.0]
        self._torso_hip = HIP_JOINT[single[0]] if (self.jt.root_virtual_torque and self.jt.stance_hip_torso
                                                   and single) else None
        self._torso_dofs = (JOINT_DOF_START[self._torso_hip] + np.arange(3) if self._torso_hip is not None
                            else np.zeros(0, dtype=int))
        d[ROOT_DOFS + self._torso_dofs, ROOT_DOFS + self._torso_dofs] = 0.0  # no PD there: nothing to predict
        if self.jt.root_virtual_torque and self._torso_hip is None:
            hips = {side: state.joint_pos[HIP_JOINT[side]] for side in ("left", "right")}
            s_map = stance_hip_map(state.root_quat_wxyz, hips, stance_weight)
            # Q_hips = S τ_r(ω_next): the root damping is implicit in the root's angular acceleration (DOFs 3-5).
            gain = root_gain_scale(self.cfg.root_yaw_gain_scale) * (self.root_kd * dt + self.root_kp * dt * dt)
            d[ROOT_DOFS:, 3:6] = s_map * gain[None, :]
        self._root_map = s_map
        self._gain = implicit_gain(mass_matrix, d)[ROOT_DOFS:, ROOT_DOFS:]

    def update(self, state: CharacterState, ref: ReferencePose) -> None:
        cfg, jt = self.cfg, self.jt
        self.model.update(state)
        mass_matrix = self.model.mass_matrix_world_layout()
        w = supporting_weights(ref.stance_weight, state.feet_pressing())
        foot_yaw = {s: rot.yaw_from_quat(state.link_quat_wxyz[state.link(f"{s}_ankle")]) for s in ("left", "right")}
        self._prepare_implicit(state, w, mass_matrix)
        frames = JointFrames(state)
        ff = np.zeros((len(JOINTS), 3))
        if jt.gravity_compensation:  # Eq. 14-15
            ff += gravity_torques(state, frames, self.mass.link_mass_kg, self.g, w, ref.ankle_world,
                                  skip_stance_ankle=jt.ipm_ankle_compensation)
        com = self.mass.com(state)
        force = np.zeros(3)
        if jt.com_virtual_force:  # Eq. 16 (first line), Eq. 19
            force += com_virtual_force(ref.com_world, ref.com_vel_world, com, self.mass.com_velocity(state),
                                       self.mass.total_kg, jt.com_force_kp_npm, jt.com_force_kd_nspm)
        f_lipm = np.zeros(3)
        if cfg.lipm_time_sync and ref.lipm is not None:  # Eq. 21-23
            f_lipm = bounded_lipm_sync_force(ref.lipm, self.mass.total_kg, self.g, cfg.lipm_force_limit_n,
                                             cfg.enforce_bounds, self.bounds, state.time_s)
            force += f_lipm
        # The whole horizontal virtual force obeys Eq. 26's bound, not only the LIPM part: a stance foot pushes the
        # COM sideways only by moving its centre of pressure, so a larger force just rolls the foot (the COM
        # velocity term alone asks for kN when the operator walks off while the character still stands).
        h_c = max(float(com[2] - min(a[2] for a in ref.ankle_world.values())), 0.1)
        f_max = bnd.lipm_force_bound_n(self.mass.total_kg, self.g, h_c)
        f_mag = float(np.linalg.norm(force[:2]))
        if f_mag > f_max:
            force[:2] *= f_max / f_mag
        if ref.character_stance is Stance.DS:  # Eq. 24
            centre = 0.5 * (ref.ankle_world["left"] + ref.ankle_world["right"])
            d_c = float(np.linalg.norm((ref.com_world - centre)[:2]))
            self.bounds.report("ds_com", d_c > bnd.ds_com_bound_m(), state.time_s,
                               "COM %.3f m from the support centre > %.3f m (Eq. 24)", d_c, bnd.ds_com_bound_m())
        moment = np.zeros((len(JOINTS), 3))  # world moments of Eq. 17 and Eq. 20
        if np.any(force):
            moment += stance_force_moments(frames, state.link_com_world, self.mass.link_mass_kg, force, w)  # Eq. 17
        if jt.ipm_ankle_compensation:  # Eq. 20
            moment += ipm_ankle_moments(ref.com_world, ref.ankle_world, w, self.mass.total_kg, self.g, foot_yaw)
        # In single stance the ankle cannot push harder than its sole allows (support.py); in double stance the
        # two feet share a larger support polygon, and a per-sole clamp there was measured to make the standing
        # character drift and fall (the ankles' PD and the clamped feedforward then fight).
        for side, ws in w.items():
            if ws >= 1.0:
                k = ANKLE_JOINT[side]
                moment[k] = limit_ankle_moment(moment[k], ref.ankle_world[side], foot_yaw[side],
                                               ws * self.mass.total_kg * self.g, self.friction)
        self._ff = ff + frames.torque_from_moment(moment)
        self._update_reference_velocity(ref)
        self._ref = ref
        self.telemetry = ControlTelemetry(force, f_lipm, self.telemetry.root_torque_nm)

    def reset(self) -> None:
        self.pid.reset()

    def torques(self, fb: JointFeedback | None) -> Torques:
        ref = self._ref
        if ref is None or fb is None:
            return Torques.zeros()
        # Eq. 13 feedback r, evaluated implicitly (stable_pd.py): position error predicted one step ahead.
        r = self.pid(fb.joint_pos, fb.joint_vel, ref.joint_pos, self._ref_vel, predict_dt_s=self.physics_dt_s)
        r_flat = flatten_joint_values(r)
        r_flat[self._torso_dofs] = 0.0
        tau_r = np.zeros(3)
        if self.jt.root_virtual_torque:  # Eq. 16 (second line), Eq. 18: -w τ_r on each stance hip
            tau_r = root_virtual_torque(ref.root_quat_wxyz, fb.root_quat_wxyz, fb.root_ang_vel_world, self.root_kp,
                                        self.root_kd, self.cfg.root_yaw_gain_scale, predict_dt_s=self.physics_dt_s)
            self.telemetry.root_torque_nm = tau_r
            r_flat += self._root_map @ tau_r
        tau = unflatten_joint_values(self._gain @ r_flat) + self._ff
        tau[~IS_BALL, 1:] = 0.0
        if self._torso_hip is not None:
            tau[self._torso_hip] = self._torso_hip_torque(fb, tau, tau_r)
        return Torques(np.clip(tau, -TORQUE_LIMIT, TORQUE_LIMIT))

    def _torso_hip_torque(self, fb: JointFeedback, tau: np.ndarray, tau_r: np.ndarray) -> np.ndarray:
        """The single-stance hip's torque (child frame) that gives the pelvis exactly the root torque of Eq. 16.

        Eq. 18 read as SIMBICON [2] does it: every joint torque on the pelvis (chest, swing hip, stance hip) acts
        on it with the opposite sign, so the stance hip takes ``τ_A = -τ_r - Σ_c τ_c`` over the pelvis's other
        children, feedback parts only; the feed-forward parts (gravity compensation, Eq. 14-15, and the COM
        virtual force, Eq. 17) stay on every joint. Without this the swing hip's reaction (hundreds of N·m when
        the swing leg reaches forward) tilts the pelvis and the upper body with it, against the root PD alone.
        """
        q_pelvis_model = rot.multiply(fb.root_quat_wxyz, Q_WORLD_MODEL)
        world = -np.asarray(tau_r, dtype=float)
        for k in PELVIS_CHILDREN:
            if k != self._torso_hip:
                r_child = rot.matrix_from_quat(rot.multiply(q_pelvis_model, fb.joint_pos[k]))
                world -= r_child @ (tau[k] - self._ff[k])
        r_stance = rot.matrix_from_quat(rot.multiply(q_pelvis_model, fb.joint_pos[self._torso_hip]))
        return self._ff[self._torso_hip] + r_stance.T @ world

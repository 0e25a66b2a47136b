"""The character as Pinocchio sees it: built once from the engine's own link and joint data, then asked at each
control tick for kinematics and dynamics (mass matrix, bias forces, gravity, frame and COM Jacobians, the centroidal
momentum map and its rate).

Pinocchio's URDF parser rejects the character's URDF (capsule collisions, ``spherical`` joints), so the model is
built in code from :class:`BodyDescription` (``PhysicsBackend.body_description``): a free-flyer root whose frame is
the engine's base frame, a ``JointModelSpherical`` per ball joint, a revolute joint per hinge, fixed links (the
pelvis on the base, the hands on the wrists) merged into their parent body and kept as frames.

Generalised coordinates are Pinocchio's: ``q`` = (base position [m], base quaternion xyzw, then per joint in
``JOINTS`` order the ball's quaternion xyzw or the hinge angle [rad]); ``v`` = (base linear and angular velocity in
the *base* frame, then per joint the ball's angular velocity in its child frame or the hinge rate). The joint
DOFs are in the same order as ``model.character``'s layout; only the root's six differ from the engine's (world
frame), by :meth:`CharacterModel.root_velocity_map`. Jacobians are returned in ``LOCAL_WORLD_ALIGNED`` form:
linear velocity of the frame's origin and angular velocity, both in world axes, (6, nv).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from stylesync import rotations as rot
from stylesync.errors import ConfigError
from stylesync.model.body_description import BodyDescription, BodyJointKind
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    FOOT_CENTER_AHEAD_OF_ANKLE_M,
    JOINT_DOF_COUNT,
    JOINT_DOF_START,
    JOINTS,
    LINK_NAMES,
    N_DOFS,
    Q_WORLD_MODEL,
    ROOT_DOFS,
    JointKind,
)
from stylesync.model.state import CharacterState

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
# Sole centre of each foot in its canonical foot frame (x forward, y left, z up) [m]: the contact frame of a sole.
SOLE_CENTER_IN_FOOT = np.array([FOOT_CENTER_AHEAD_OF_ANKLE_M, 0.0, -ANKLE_HEIGHT_M])
SOLE_FRAMES = {"left": "left_sole", "right": "right_sole"}
HAND_FRAMES = {"left": "left_wrist", "right": "right_wrist"}


def _se3(pos: np.ndarray, quat_wxyz: np.ndarray) -> pin.SE3:
    return pin.SE3(rot.matrix_from_quat(np.asarray(quat_wxyz, dtype=float)), np.asarray(pos, dtype=float))


def _inertia(mass_kg: float, inertia_diag: np.ndarray, pos: np.ndarray, quat_wxyz: np.ndarray) -> pin.Inertia:
    """A body's spatial inertia in its link frame, from its COM frame's pose and principal moments."""
    r = rot.matrix_from_quat(np.asarray(quat_wxyz, dtype=float))
    return pin.Inertia(float(mass_kg), np.asarray(pos, dtype=float), r @ np.diag(inertia_diag) @ r.T)


def _depth_first(body: BodyDescription) -> list[int]:
    """Link indices in depth-first order (children in the engine's order)."""
    children: dict[int, list[int]] = {}
    for i, link in enumerate(body.links):
        children.setdefault(link.parent, []).append(i)
    order: list[int] = []
    stack = list(reversed(children.get(-1, [])))
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children.get(i, [])))
    return order


def build_pinocchio_model(body: BodyDescription, gravity_mps2: float) -> pin.Model:
    """The Pinocchio model of ``body``: a free-flyer root, one joint per moving link, fixed links merged."""
    model = pin.Model()
    model.gravity.linear = np.array([0.0, 0.0, -gravity_mps2])
    root = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_free_flyer")
    model.appendBodyToJoint(root, pin.Inertia(body.base_mass_kg, np.zeros(3), np.diag(body.base_inertia_diag_kgm2)),
                            pin.SE3.Identity())
    base_frame = model.addFrame(pin.Frame("base", root, 0, pin.SE3.Identity(), pin.FrameType.BODY))
    # Per link: the Pinocchio joint it moves with, its frame in that joint's frame, its frame's index. Links are
    # added depth first: Pinocchio's algorithms need each joint's subtree to follow it contiguously (the engine's
    # order puts the hips between the chest and the shoulders).
    attach: dict[int, tuple[int, pin.SE3, int]] = {}
    for index in _depth_first(body):
        link = body.links[index]
        if link.parent < 0:
            joint_parent, t_joint_parent_inertial, parent_frame = root, pin.SE3.Identity(), base_frame
        else:
            joint_parent, t_joint_parent_link, parent_frame = attach[link.parent]
            parent = body.links[link.parent]
            t_joint_parent_inertial = t_joint_parent_link * _se3(parent.inertial_pos_in_link,
                                                                 parent.inertial_quat_in_link_wxyz)
        placement = t_joint_parent_inertial * _se3(link.joint_pos_in_parent_inertial,
                                                   link.joint_quat_in_parent_inertial_wxyz)
        inertia = _inertia(link.mass_kg, link.inertia_diag_kgm2, link.inertial_pos_in_link,
                           link.inertial_quat_in_link_wxyz)
        if link.joint_kind is BodyJointKind.FIXED:
            model.appendBodyToJoint(joint_parent, placement.act(inertia), pin.SE3.Identity())
            frame = model.addFrame(pin.Frame(link.name, joint_parent, parent_frame, placement, pin.FrameType.BODY))
            attach[index] = (joint_parent, placement, frame)
            continue
        if link.joint_kind is BodyJointKind.SPHERICAL:
            joint_model = pin.JointModelSpherical()
        else:
            axis = np.asarray(link.joint_axis, dtype=float)
            joint_model = pin.JointModelRevoluteUnaligned(axis / np.linalg.norm(axis))
        joint = model.addJoint(joint_parent, joint_model, placement, link.name)
        model.appendBodyToJoint(joint, inertia, pin.SE3.Identity())
        frame = model.addFrame(pin.Frame(link.name, joint, parent_frame, pin.SE3.Identity(), pin.FrameType.BODY))
        attach[index] = (joint, pin.SE3.Identity(), frame)
    # Sole contact frames, axes canonical (z up with the foot flat): the model's link axes are Y-up.
    r_link_sole = rot.matrix_from_quat(rot.conjugate(Q_WORLD_MODEL))
    for side, name in SOLE_FRAMES.items():
        joint, t_joint_link, frame = attach[body.link_index(f"{side}_ankle")]
        placement = t_joint_link * pin.SE3(r_link_sole, r_link_sole @ SOLE_CENTER_IN_FOOT)
        model.addFrame(pin.Frame(name, joint, frame, placement, pin.FrameType.OP_FRAME))
    return model


class CharacterModel:
    """One object that everything asks: indices, frames, kinematics, dynamics of the character at one state.

    :meth:`update` evaluates everything for a state (one call per control tick); the properties then read the
    results. World frame z up; the model's own link axes are the URDF's (Y up), the contact frames' canonical.
    """

    def __init__(self, body: BodyDescription, gravity_mps2: float):
        self.model = build_pinocchio_model(body, gravity_mps2)
        self.data = self.model.createData()
        self.nq, self.nv = self.model.nq, self.model.nv
        if self.nv != N_DOFS:
            raise ConfigError(f"character model has {self.nv} DOFs, the character description {N_DOFS}")
        self.gravity_mps2 = gravity_mps2
        # Position limits of the limited joints (the hinges), by joint name [rad]
        self.joint_limits_rad: dict[str, tuple[float, float]] = {
            link.name: link.joint_limits_rad for link in body.links if link.joint_limits_rad is not None}
        self.total_mass_kg = float(pin.computeTotalMass(self.model))
        self._frame_ids = {f.name: i for i, f in enumerate(self.model.frames)}
        self.link_frame_ids = [self._frame_ids[n] for n in LINK_NAMES]
        # Index maps from the state's (n_joints, 4) / (n_joints, 3) arrays to q and v (wxyz -> xyzw for balls).
        q_idx, v_idx, q_flat, v_flat = [], [], [], []
        self._hinge_q_of_dof = np.full(self.nv, -1)  # a hinge's index in q by its DOF in the character's layout
        perm = np.arange(self.nv)  # perm[i]: Pinocchio's index of DOF i of the character's layout
        for k, spec in enumerate(JOINTS):
            jid = self.model.getJointId(spec.name)
            iq, iv = self.model.idx_qs[jid], self.model.idx_vs[jid]
            perm[ROOT_DOFS + JOINT_DOF_START[k]:ROOT_DOFS + JOINT_DOF_START[k] + JOINT_DOF_COUNT[k]] = \
                np.arange(iv, iv + JOINT_DOF_COUNT[k])
            if spec.kind is JointKind.BALL:
                q_idx += [iq, iq + 1, iq + 2, iq + 3]
                q_flat += [4 * k + 1, 4 * k + 2, 4 * k + 3, 4 * k]
                v_idx += [iv, iv + 1, iv + 2]
                v_flat += [3 * k, 3 * k + 1, 3 * k + 2]
            else:
                self._hinge_q_of_dof[ROOT_DOFS + JOINT_DOF_START[k]] = iq
                q_idx.append(iq)
                q_flat.append(4 * k)
                v_idx.append(iv)
                v_flat.append(3 * k)
        self._q_idx, self._q_flat = np.array(q_idx), np.array(q_flat)
        self._v_idx, self._v_flat = np.array(v_idx), np.array(v_flat)
        self._perm = perm
        self.q = pin.neutral(self.model)
        self.v = np.zeros(self.nv)
        self._zero_a = np.zeros(self.nv)
        self.mass_matrix = np.zeros((self.nv, self.nv))
        self.revision = 0  # counts the updates: what was computed from the model can tell whether it is current

    # ---- indices -----------------------------------------------------------------------------------------
    def frame_id(self, name: str) -> int:
        try:
            return self._frame_ids[name]
        except KeyError:
            raise ConfigError(f"no frame '{name}' in the character model; frames: {', '.join(self._frame_ids)}") \
                from None

    # ---- state -------------------------------------------------------------------------------------------
    def configuration(self, root_pos_world: np.ndarray, root_quat_wxyz: np.ndarray,
                      joint_pos: np.ndarray) -> np.ndarray:
        """q (nq,) from the root pose (canonical orientation) and the joints as in ``CharacterState``."""
        q = np.empty(self.nq)
        q[:3] = root_pos_world
        q_base = rot.multiply(np.asarray(root_quat_wxyz, dtype=float), Q_WORLD_MODEL)
        q[3:6], q[6] = q_base[1:], q_base[0]
        q[self._q_idx] = np.asarray(joint_pos, dtype=float).flat[self._q_flat]
        return q

    def velocity(self, q: np.ndarray, root_lin_vel_world: np.ndarray, root_ang_vel_world: np.ndarray,
                 joint_vel: np.ndarray) -> np.ndarray:
        """Pinocchio's v (nv,) at configuration ``q``: the root's world velocities turned into the base frame."""
        r = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
        v = np.empty(self.nv)
        v[:3] = r.T @ root_lin_vel_world
        v[3:6] = r.T @ root_ang_vel_world
        v[self._v_idx] = np.asarray(joint_vel, dtype=float).flat[self._v_flat]
        return v

    def root_velocity_map(self) -> np.ndarray:
        """(nv, nv) T with v = T v_world_layout at the current state: the engine's layout has the root's linear and
        angular velocity in world axes; T = blockdiag(Rᵀ, Rᵀ, I)."""
        r = self.data.oMi[1].rotation
        t = np.eye(self.nv)
        t[:3, :3] = r.T
        t[3:6, 3:6] = r.T
        return t

    def update(self, state: CharacterState) -> None:
        """Evaluate kinematics and dynamics at ``state``: frames, Jacobians, M (symmetric), bias forces h(q, v)
        (Coriolis, centrifugal and gravity), gravity g(q), COM, its Jacobian, the centroidal map and its rate."""
        q = self.configuration(state.root_pos_world, state.root_quat_wxyz, state.joint_pos)
        self.update_qv(q, self.velocity(q, state.root_lin_vel_world, state.root_ang_vel_world, state.joint_vel))

    def update_qv(self, q: np.ndarray, v: np.ndarray) -> None:
        """:meth:`update` from Pinocchio's q and v. Results are in the character's DOF layout."""
        m, d, p = self.model, self.data, self._perm
        self.revision += 1
        self.q, self.v = q, v.take(p)
        # Frame accelerations at q̈ = 0 are the drift terms J̇ q̇ of the tasks.
        pin.forwardKinematics(m, d, q, v, self._zero_a)
        pin.computeJointJacobians(m, d)  # from the placements just computed
        pin.updateFramePlacements(m, d)
        pin.crba(m, d, q, pin.Convention.WORLD)
        self.mass_matrix = d.M.take(p, 0).take(p, 1)  # (nv, nv); crba fills M whole
        self.bias_forces = pin.nonLinearEffects(m, d, q, v).take(p)  # (nv,) C(q, v) v + g(q) [N, N·m]
        pin.computeCentroidalMapTimeVariation(m, d, q, v)  # also the COM and the centroidal momentum
        self.centroidal_map = d.Ag.take(p, 1)  # (6, nv): [linear; angular about the COM] momentum
        self.centroidal_map_dot_v = d.dAg @ v  # (6,) Ȧ_g v
        self.com_world = d.com[0].copy()  # (3,) [m]
        self.com_vel_world = (d.Ag[:3] @ v) / self.total_mass_kg  # (3,) [m/s]

    @property
    def centroidal_angular_momentum(self) -> np.ndarray:
        """(3,) the whole body's angular momentum about its COM at the last update, world axes [kg·m²/s]: the
        angular rows of A_g v."""
        return (self.centroidal_map @ self.v)[3:]

    @property
    def gravity_forces(self) -> np.ndarray:
        """(nv,) generalised gravity g(q) at the last update [N, N·m]."""
        return pin.computeGeneralizedGravity(self.model, self.data, self.q)[self._perm]

    @property
    def com_jacobian(self) -> np.ndarray:
        """(3, nv) Jacobian of the COM at the last update."""
        return pin.jacobianCenterOfMass(self.model, self.data, self.q, False)[:, self._perm]

    # ---- frames ------------------------------------------------------------------------------------------
    def frame_placement(self, frame: int) -> pin.SE3:
        """The frame's world placement at the last update (Pinocchio's own object: read it before the next)."""
        return self.data.oMf[frame]

    def frame_position(self, frame: int) -> np.ndarray:
        return self.data.oMf[frame].translation.copy()

    def frame_rotation(self, frame: int) -> np.ndarray:
        return self.data.oMf[frame].rotation.copy()

    def frame_jacobian(self, frame: int) -> np.ndarray:
        """(6, nv) [linear; angular] Jacobian of the frame, LOCAL_WORLD_ALIGNED."""
        return pin.getFrameJacobian(self.model, self.data, frame, _LWA).take(self._perm, 1)

    def frame_velocity(self, frame: int) -> np.ndarray:
        """(6,) [linear; angular] velocity of the frame's origin, world axes [m/s, rad/s]."""
        return pin.getFrameVelocity(self.model, self.data, frame, _LWA).vector.copy()

    def frame_drift(self, frame: int) -> np.ndarray:
        """(6,) J̇ q̇: the frame's classical acceleration at q̈ = 0, world axes [m/s², rad/s²]."""
        return pin.getFrameClassicalAcceleration(self.model, self.data, frame, _LWA).vector.copy()

    def link_positions(self) -> np.ndarray:
        """(n_links, 3) world origins of the links of ``LINK_NAMES`` [m]."""
        return np.array([self.data.oMf[f].translation for f in self.link_frame_ids])

    def mass_matrix_world_layout(self) -> np.ndarray:
        """M in the engine's layout (root velocities in world axes): Tᵀ M T."""
        t = self.root_velocity_map()
        return t.T @ self.mass_matrix @ t

    def rest_distance(self, frame_a: str, frame_b: str) -> float:
        """Distance between two frames' origins in the rest pose [m] (a segment's length)."""
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        a, b = data.oMf[self.frame_id(frame_a)], data.oMf[self.frame_id(frame_b)]
        return float(np.linalg.norm(a.translation - b.translation))

    def joint_position(self, dof: int) -> float:
        """A hinge's angle [rad] by its index in the character's DOF layout."""
        return float(self.q[self._hinge_q_of_dof[dof]])

    def joint_positions(self, dofs: np.ndarray) -> np.ndarray:
        """Hinges' angles [rad] by their indices in the character's DOF layout."""
        return self.q[self._hinge_q_of_dof[dofs]]

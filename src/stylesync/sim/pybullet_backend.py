"""PyBullet 3.2.7 implementation of :class:`PhysicsBackend` (Sec. 7.1).

The only module (with ``sim/scene.py``) that imports pybullet. PyBullet quaternions are (x, y, z, w); they are
converted here, at the boundary. The character is moved by joint torques only: the default joint motors are
disabled at load time and :meth:`apply_torques` is the only actuation.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import sys
from typing import Any

import numpy as np
import pybullet as pb
import pybullet_data
from pybullet_utils.bullet_client import BulletClient

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.errors import SimulationError
from stylesync.model.body_description import BodyDescription, BodyJointKind, LinkDescription
from stylesync.model.character import (
    FOOT_LINKS,
    JOINT_NAMES,
    JOINTS,
    LINK_NAMES,
    Q_WORLD_MODEL,
    URDF_GLOBAL_SCALING,
    URDF_PATH_IN_PYBULLET_DATA,
    JointKind,
)
from stylesync.model.state import CharacterState, JointFeedback, LinkShape, MassProperties, Torques
from stylesync.sim.backend import PhysicsBackend

_Q_MODEL_WORLD = rot.conjugate(Q_WORLD_MODEL)
SOCCER_BALL_URDF = "soccerball.urdf"
# The ground is pybullet_data's plane.urdf, whose collision shape is a box 200 m square (its top face at z = 0). It
# is kept centred on the multiple of GROUND_TILE_M nearest the character (PyBulletBackend._keep_ground_under): the
# character always has at least GROUND_TILE_M / 2 of ground around it, wherever a recording puts its operator or a
# long walk takes it; near the origin the ground never moves, and its contacts stay those of the same box [m].
GROUND_TILE_M = 100.0


@contextlib.contextmanager
def _quiet_stdout():
    """Silence C-level stdout/stderr (file descriptors 1 and 2) for the duration."""
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


_SHAPE_KIND = {pb.GEOM_SPHERE: "sphere", pb.GEOM_CAPSULE: "capsule", pb.GEOM_BOX: "box"}


# A PyBullet link orientation (x, y, z, w) to our canonical one (w, x, y, z): reordered, then times
# _Q_MODEL_WORLD on the right, one linear map (4x4, acting on rows).
_CANONICAL_FROM_LINK_XYZW_T = np.array([rot.multiply(rot.wxyz_from_xyzw(e), _Q_MODEL_WORLD) for e in np.eye(4)])


def _canonical_from_link_xyzw(q_xyzw) -> np.ndarray:
    return np.asarray(q_xyzw, dtype=float) @ _CANONICAL_FROM_LINK_XYZW_T


class _BoundClient:
    """A BulletClient whose engine calls are bound once: BulletClient makes a new ``functools.partial`` (binding
    its client id) on every attribute access, a measurable cost for the calls made at every physics step."""

    def __init__(self, client: BulletClient):
        self._client = client

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._client, name)
        self.__dict__[name] = attr
        return attr


class PyBulletBackend(PhysicsBackend):
    def __init__(self, world: WorldConfig, physics_hz: float, gui: bool = False, fixed_root: bool = False):
        try:
            self._pb = _BoundClient(BulletClient(connection_mode=pb.GUI if gui else pb.DIRECT))
        except Exception as exc:  # pybullet raises a bare error when no display is available
            raise SimulationError(f"could not start PyBullet ({'GUI' if gui else 'DIRECT'}): {exc}") from exc
        c = self._pb
        c.setAdditionalSearchPath(pybullet_data.getDataPath())
        c.setGravity(0.0, 0.0, -world.gravity_mps2)
        c.setTimeStep(1.0 / physics_hz)
        c.setPhysicsEngineParameter(numSolverIterations=10)
        self._world = world
        self._fixed_root = fixed_root
        self.plane = c.loadURDF("plane.urdf", [0, 0, 0], useFixedBase=True)
        self._ground_centre_xy = (0.0, 0.0)
        with _quiet_stdout():  # the URDF importer prints warnings about axis-less spherical joints
            self.body = c.loadURDF(
                URDF_PATH_IN_PYBULLET_DATA,
                [0.0, 0.0, 1.0],
                rot.xyzw_from_wxyz(Q_WORLD_MODEL).tolist(),
                globalScaling=URDF_GLOBAL_SCALING,
                useFixedBase=fixed_root,
                flags=pb.URDF_MAINTAIN_LINK_ORDER,
            )
        index_by_name = {c.getJointInfo(self.body, j)[1].decode(): j for j in range(c.getNumJoints(self.body))}
        missing = [n for n in JOINT_NAMES if n not in index_by_name]
        if missing:
            raise SimulationError(f"character model lacks joints {missing}")
        self._joint_idx = [index_by_name[n] for n in JOINT_NAMES]
        self._link_idx = [index_by_name[n] for n in LINK_NAMES]
        self._foot_idx = {index_by_name[n]: n for n in FOOT_LINKS}
        self._is_ball = np.array([j.kind is JointKind.BALL for j in JOINTS])
        self._pos_flat, self._vel_flat = self._feedback_maps()
        self._last_torque_values: np.ndarray | None = None  # the last torques applied, and their PyBullet form
        self._last_forces: list[list[float]] = []
        for j, spec in zip(self._joint_idx, JOINTS, strict=True):
            if spec.kind is JointKind.BALL:
                c.setJointMotorControlMultiDof(
                    self.body, j, pb.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                    positionGain=0, velocityGain=0, force=[0, 0, 0],
                )
            else:
                c.setJointMotorControl2(self.body, j, pb.VELOCITY_CONTROL, force=0)
        for link in [-1, *range(c.getNumJoints(self.body))]:
            c.changeDynamics(
                self.body, link, contactStiffness=world.contact_stiffness_npm,
                contactDamping=world.contact_damping_nspm, lateralFriction=world.friction,
                frictionAnchor=int(world.friction_anchor),
            )
        c.changeDynamics(
            self.plane, -1, contactStiffness=world.contact_stiffness_npm,
            contactDamping=world.contact_damping_nspm, lateralFriction=world.friction,
        )
        masses = [c.getDynamicsInfo(self.body, i)[0] for i in self._link_idx]
        base_mass = c.getDynamicsInfo(self.body, -1)[0]
        masses[0] += base_mass  # the 0.1 g dummy base is welded to the pelvis
        self._mass = MassProperties(np.array(masses))
        self.balls: list[int] = []
        self._all_joints = list(range(c.getNumJoints(self.body)))
        self._raw: tuple | None = None  # the engine's state as last read, until the next step or reset

    # ------------------------------------------------------------------------------------------------------
    def reset(self, root_pos_world, root_quat_wxyz, joint_pos=None) -> None:
        c = self._pb
        self._raw = None
        q_link = rot.multiply(np.asarray(root_quat_wxyz, dtype=float), Q_WORLD_MODEL)
        c.resetBasePositionAndOrientation(self.body, list(root_pos_world), rot.xyzw_from_wxyz(q_link).tolist())
        c.resetBaseVelocity(self.body, [0, 0, 0], [0, 0, 0])
        self._keep_ground_under(root_pos_world)
        for k, j in enumerate(self._joint_idx):
            if self._is_ball[k]:
                q = rot.IDENTITY_WXYZ if joint_pos is None else rot.normalize(joint_pos[k])
                c.resetJointStateMultiDof(self.body, j, rot.xyzw_from_wxyz(q).tolist(), [0, 0, 0])
            else:
                angle = 0.0 if joint_pos is None else float(joint_pos[k, 0])
                c.resetJointState(self.body, j, angle, 0.0)

    def _keep_ground_under(self, pos_world) -> None:
        """Centre the ground on the multiple of GROUND_TILE_M nearest ``pos_world`` (horizontally) if it is not
        there yet: the same surface (z = 0) goes on under the character; no force acts on it."""
        centre = (GROUND_TILE_M * round(float(pos_world[0]) / GROUND_TILE_M),
                  GROUND_TILE_M * round(float(pos_world[1]) / GROUND_TILE_M))
        if centre != self._ground_centre_xy:
            self._pb.resetBasePositionAndOrientation(self.plane, [centre[0], centre[1], 0.0], [0.0, 0.0, 0.0, 1.0])
            self._ground_centre_xy = centre

    def set_velocities(self, root_lin_vel_world, root_ang_vel_world, joint_vel) -> None:
        """Initial velocities (tests of the kinematics): root [m/s], [rad/s] (world), joints as in
        ``CharacterState.joint_vel``."""
        c = self._pb
        self._raw = None
        c.resetBaseVelocity(self.body, list(root_lin_vel_world), list(root_ang_vel_world))
        for k, j in enumerate(self._joint_idx):
            pos = c.getJointStateMultiDof(self.body, j)[0]
            vel = list(joint_vel[k]) if self._is_ball[k] else [float(joint_vel[k, 0])]
            c.resetJointStateMultiDof(self.body, j, pos, vel)

    def mass_properties(self) -> MassProperties:
        return self._mass

    def body_description(self) -> BodyDescription:
        c = self._pb
        kinds = {pb.JOINT_FIXED: BodyJointKind.FIXED, pb.JOINT_SPHERICAL: BodyJointKind.SPHERICAL,
                 pb.JOINT_REVOLUTE: BodyJointKind.REVOLUTE}
        links = []
        for j in range(c.getNumJoints(self.body)):
            info, dyn = c.getJointInfo(self.body, j), c.getDynamicsInfo(self.body, j)
            if info[2] not in kinds:
                raise SimulationError(f"character joint '{info[1].decode()}' has an unsupported type {info[2]}")
            links.append(LinkDescription(
                name=info[12].decode(), parent=int(info[16]), joint_kind=kinds[info[2]],
                joint_axis=np.array(info[13], dtype=float),
                joint_pos_in_parent_inertial=np.array(info[14], dtype=float),
                joint_quat_in_parent_inertial_wxyz=rot.wxyz_from_xyzw(np.array(info[15], dtype=float)),
                mass_kg=float(dyn[0]), inertia_diag_kgm2=np.array(dyn[2], dtype=float),
                inertial_pos_in_link=np.array(dyn[3], dtype=float),
                inertial_quat_in_link_wxyz=rot.wxyz_from_xyzw(np.array(dyn[4], dtype=float)),
                joint_limits_rad=(float(info[8]), float(info[9])) if info[8] < info[9] else None))
        base = c.getDynamicsInfo(self.body, -1)
        if np.any(np.abs(base[3]) > 0) or np.any(np.abs(np.array(base[4]) - (0, 0, 0, 1)) > 0):
            raise SimulationError("the character's base must have its inertial frame at its link frame")
        return BodyDescription(float(base[0]), np.array(base[2], dtype=float), tuple(links))

    def _read_raw(self) -> tuple:
        """Base pose and velocity and every joint's state, read once per engine state: the joint feedback, the
        character state and the mass matrix of one control tick share it."""
        if self._raw is None:
            c = self._pb
            base_pos, base_xyzw = c.getBasePositionAndOrientation(self.body)
            lin_vel, ang_vel = c.getBaseVelocity(self.body)
            self._raw = (base_pos, base_xyzw, lin_vel, ang_vel, c.getJointStatesMultiDof(self.body, self._all_joints))
        return self._raw

    def read_state(self, time_s: float) -> CharacterState:
        c = self._pb
        fb = self.read_joint_feedback()
        base_pos, _, lin_vel, _, _ = self._read_raw()
        self._keep_ground_under(base_pos)
        links = c.getLinkStates(self.body, self._link_idx, computeLinkVelocity=1, computeForwardKinematics=1)
        # One array of each link's COM (3), frame origin (3), orientation xyzw (4), COM velocity (3), angular
        # velocity (3), split into views.
        table = np.fromiter(itertools.chain.from_iterable(ls[0] + ls[4] + ls[5] + ls[6] + ls[7] for ls in links), float,
                            16 * len(links)).reshape(-1, 16)
        com, origin, quat_xyzw = table[:, 0:3], table[:, 3:6], table[:, 6:10]
        com_vel, ang = table[:, 10:13], table[:, 13:16]
        quat = quat_xyzw @ _CANONICAL_FROM_LINK_XYZW_T
        foot_force = {name: 0.0 for name in FOOT_LINKS}
        non_foot = False
        for cp in c.getContactPoints(bodyA=self.body, bodyB=self.plane):
            link = cp[3]
            if link in self._foot_idx:
                foot_force[self._foot_idx[link]] += cp[9]
            else:
                non_foot = True
        return CharacterState(
            time_s=time_s,
            root_pos_world=np.array(base_pos),
            root_quat_wxyz=fb.root_quat_wxyz,
            root_lin_vel_world=np.array(lin_vel),
            root_ang_vel_world=fb.root_ang_vel_world,
            joint_pos=fb.joint_pos,
            joint_vel=fb.joint_vel,
            link_com_world=com,
            link_com_vel_world=com_vel,
            link_origin_world=origin,
            link_quat_wxyz=quat,
            link_ang_vel_world=ang,
            foot_contact_force_n=foot_force,
            non_foot_ground_contact=non_foot,
        )

    def read_joint_feedback(self) -> JointFeedback:
        _, base_q, _, ang_vel, all_states = self._read_raw()
        states = [all_states[j] for j in self._joint_idx]
        # The engine's values in joint order (ball: x, y, z, w and 3 rates; hinge: 1 and 1), scattered into the
        # (n, 4) wxyz / (n, 3) layout by index maps built once (_feedback_maps).
        pos = np.zeros((len(states), 4))
        vel = np.zeros((len(states), 3))
        pos.flat[self._pos_flat] = np.fromiter(itertools.chain.from_iterable(st[0] for st in states), float,
                                               len(self._pos_flat))
        vel.flat[self._vel_flat] = np.fromiter(itertools.chain.from_iterable(st[1] for st in states), float,
                                               len(self._vel_flat))
        return JointFeedback(pos, vel, _canonical_from_link_xyzw(base_q), np.array(ang_vel))

    def _feedback_maps(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat indices into (n, 4) positions and (n, 3) velocities of the engine's per-joint values, in order."""
        pos, vel = [], []
        for k, ball in enumerate(self._is_ball):
            pos += [4 * k + 1, 4 * k + 2, 4 * k + 3, 4 * k] if ball else [4 * k]  # x, y, z, w -> w, x, y, z
            vel += [3 * k, 3 * k + 1, 3 * k + 2] if ball else [3 * k]
        return np.array(pos), np.array(vel)

    def apply_torques(self, torques: Torques) -> None:
        v = torques.values
        # The same array as the last step's (a controller holding its torques over a control tick): its PyBullet
        # form is reused. Torques are values, never changed in place once applied.
        if v is self._last_torque_values:
            forces = self._last_forces
        else:
            if not np.all(np.isfinite(v)):
                raise SimulationError("non-finite joint torque requested; refusing to drive the character with it")
            rows = v.tolist()
            forces = [rows[k] if self._is_ball[k] else [rows[k][0]] for k in range(len(self._joint_idx))]
            self._last_torque_values, self._last_forces = v, forces
        self._pb.setJointMotorControlMultiDofArray(self.body, self._joint_idx, pb.TORQUE_CONTROL, forces=forces)

    def step(self) -> None:
        self._raw = None
        self._pb.stepSimulation()

    def collision_shapes(self) -> list[LinkShape]:
        c = self._pb
        shapes = []
        for i, link in enumerate(self._link_idx):
            _, _, _, inertial_pos, inertial_xyzw, *_ = c.getDynamicsInfo(self.body, link)
            q_inertial = rot.wxyz_from_xyzw(inertial_xyzw)
            for data in c.getCollisionShapeData(self.body, link):
                geom, dims, pos, xyzw = data[2], data[3], data[5], data[6]
                kind = _SHAPE_KIND.get(geom)
                if kind is None:
                    continue
                # link COM frame (PyBullet's inertial frame) -> canonical link axes: the canonical orientation is
                # the PyBullet one times Q_MODEL_WORLD, so a vector in PyBullet link axes is Q_WORLD_MODEL v.
                q_rel = rot.multiply(Q_WORLD_MODEL, rot.multiply(q_inertial, rot.wxyz_from_xyzw(xyzw)))
                p_rel = rot.rotate(rot.multiply(Q_WORLD_MODEL, q_inertial), np.asarray(pos, dtype=float))
                size = (float(dims[0]),) if kind == "sphere" else (
                    (float(dims[0]), float(dims[1])) if kind == "capsule" else tuple(float(d) for d in dims[:3]))
                shapes.append(LinkShape(i, kind, size, p_rel, q_rel))
        return shapes

    def close(self) -> None:
        try:
            self._pb.disconnect()
        except pb.error:
            pass

    # ---- scripted disturbances and rendering (not actuation of the character) ------------------------------
    def throw_ball(self, pos_world, vel_world, mass_kg: float = 0.43, radius_m: float = 0.11) -> int:
        """Spawn a football at ``pos_world`` [m] moving at ``vel_world`` [m/s] (a scripted disturbance)."""
        c = self._pb
        ball = c.loadURDF(SOCCER_BALL_URDF, list(pos_world), globalScaling=2 * radius_m)
        c.changeDynamics(ball, -1, mass=mass_kg, lateralFriction=0.6, restitution=0.5,
                         rollingFriction=0.001, spinningFriction=0.001)
        c.resetBaseVelocity(ball, list(vel_world), [0, 0, 0])
        self.balls.append(ball)
        return ball

    def body_position(self, body: int) -> np.ndarray:
        return np.array(self._pb.getBasePositionAndOrientation(body)[0])

    def render_rgb(self, target_world, width: int = 320, height: int = 240, distance_m: float = 3.0,
                   yaw_deg: float = 60.0, pitch_deg: float = -15.0) -> np.ndarray:
        """An RGB image (height, width, 3) uint8 from the engine's software renderer."""
        c = self._pb
        view = c.computeViewMatrixFromYawPitchRoll(list(target_world), distance_m, yaw_deg, pitch_deg, 0, 2)
        proj = c.computeProjectionMatrixFOV(50, width / height, 0.05, 50)
        img = c.getCameraImage(width, height, view, proj, renderer=pb.ER_TINY_RENDERER)
        rgba = np.reshape(np.asarray(img[2], dtype=np.uint8), (height, width, 4))
        return rgba[:, :, :3].copy()

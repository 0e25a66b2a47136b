"""The typed values that cross from the engine to the pipeline: the character's state, its mass properties, the
torques sent back.

World frame: z up, x forward, y left, metres, seconds, radians. Quaternions (w, x, y, z). Ball-joint rotations,
velocities and torques are expressed in the joint's child link frame (model axes); hinge values are scalars about the
hinge axis.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from stylesync.model.character import JOINT_NAMES, LINK_NAMES

CONTACT_FORCE_N = 5.0  # a foot pressing the ground harder than this is in contact (supports the body) [N]


@dataclass
class CharacterState:
    """Full kinematic state of the character at one instant (read at the control rate)."""

    time_s: float
    root_pos_world: np.ndarray  # (3,) pelvis frame origin [m]
    root_quat_wxyz: np.ndarray  # (4,) canonical pelvis orientation (identity when standing, facing +x)
    root_lin_vel_world: np.ndarray  # (3,) [m/s]
    root_ang_vel_world: np.ndarray  # (3,) [rad/s]
    joint_pos: np.ndarray  # (n_joints, 4): ball joints wxyz (model axes), hinge angle in column 0 [rad]
    joint_vel: np.ndarray  # (n_joints, 3): ball joints child-frame angular velocity, hinge rate in col 0
    link_com_world: np.ndarray  # (n_links, 3) centre of mass of each link [m]
    link_com_vel_world: np.ndarray  # (n_links, 3) [m/s]
    link_origin_world: np.ndarray  # (n_links, 3) link frame origin = joint position [m]
    link_quat_wxyz: np.ndarray  # (n_links, 4) canonical world orientation of each link
    link_ang_vel_world: np.ndarray  # (n_links, 3) [rad/s]
    foot_contact_force_n: dict[str, float]  # normal ground force per foot link [N]
    non_foot_ground_contact: bool  # a link other than a foot touches the ground

    def link(self, name: str) -> int:
        return LINK_NAMES.index(name)

    def feet_pressing(self) -> dict[str, bool]:
        """Per side ("left", "right"), whether that foot presses the ground harder than CONTACT_FORCE_N."""
        return {s: self.foot_contact_force_n[f"{s}_ankle"] > CONTACT_FORCE_N for s in ("left", "right")}


@dataclass(frozen=True)
class MassProperties:
    link_mass_kg: np.ndarray  # (n_links,)

    @functools.cached_property
    def total_kg(self) -> float:
        return float(self.link_mass_kg.sum())

    @functools.cached_property
    def _weights(self) -> np.ndarray:
        return self.link_mass_kg / self.total_kg

    def com(self, state: CharacterState) -> np.ndarray:
        """Whole-body centre of mass [m] (world)."""
        return self._weights @ state.link_com_world

    def com_velocity(self, state: CharacterState) -> np.ndarray:
        return self._weights @ state.link_com_vel_world

    def com_velocity_carried(self, state: CharacterState, links: tuple[int, ...], carrier: int) -> np.ndarray:
        """Whole-body COM velocity [m/s] (world) with the ``links`` (indices into LINK_NAMES) moving as the link
        ``carrier`` does: their own motion relative to it left out."""
        vel, carried = state.link_com_vel_world, list(links)
        return self._weights @ vel + self._weights[carried] @ (vel[carrier] - vel[carried])


@dataclass
class JointFeedback:
    """What the per-physics-step PD needs, read cheaply every step."""

    joint_pos: np.ndarray  # (n_joints, 4) as in CharacterState
    joint_vel: np.ndarray  # (n_joints, 3)
    root_quat_wxyz: np.ndarray  # (4,) canonical pelvis orientation
    root_ang_vel_world: np.ndarray  # (3,)


@dataclass(frozen=True)
class LinkShape:
    """One collision shape of a character link, for drawing.

    ``kind`` is "sphere" (size = radius), "capsule" (size = (length of the cylinder part, radius), axis = local z)
    or "box" (size = full extents x, y, z) [m]. ``pos_link`` and ``quat_link_wxyz`` place the shape relative to the
    link's centre of mass, in the link's canonical axes (those of ``CharacterState.link_quat_wxyz``).
    """

    link: int  # index in LINK_NAMES
    kind: str
    size: tuple[float, ...]
    pos_link: np.ndarray
    quat_link_wxyz: np.ndarray


@dataclass
class Torques:
    """Joint torques for one physics step: (n_joints, 3) child-frame for ball joints, column 0 for hinges [N·m]."""

    values: np.ndarray

    @staticmethod
    def zeros() -> Torques:
        return Torques(np.zeros((len(JOINT_NAMES), 3)))

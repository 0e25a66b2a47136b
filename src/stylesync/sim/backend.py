"""The physics backend interface: what the session asks of an engine.

Only ``sim/`` imports an engine. The values that cross the interface live in ``model/state.py``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from stylesync.model.body_description import BodyDescription
from stylesync.model.state import CharacterState, JointFeedback, LinkShape, MassProperties, Torques

__all__ = ["PhysicsBackend", "CharacterState", "JointFeedback", "LinkShape", "MassProperties", "Torques"]


class PhysicsBackend(ABC):
    """A physics engine holding one character on a flat ground, stepped at a fixed rate."""

    @abstractmethod
    def reset(
        self, root_pos_world: np.ndarray, root_quat_wxyz: np.ndarray, joint_pos: np.ndarray | None = None
    ) -> None: ...

    @abstractmethod
    def set_velocities(self, root_lin_vel_world: np.ndarray, root_ang_vel_world: np.ndarray,
                       joint_vel: np.ndarray) -> None:
        """Initial velocities after :meth:`reset`: root [m/s], [rad/s] (world), joints as
        ``CharacterState.joint_vel``."""

    @abstractmethod
    def mass_properties(self) -> MassProperties: ...

    @abstractmethod
    def body_description(self) -> BodyDescription:
        """The character's links and joints as the engine holds them (masses, inertias, joint frames), from which
        ``model.character_model.CharacterModel`` is built."""

    @abstractmethod
    def read_state(self, time_s: float) -> CharacterState: ...

    @abstractmethod
    def read_joint_feedback(self) -> JointFeedback: ...

    @abstractmethod
    def apply_torques(self, torques: Torques) -> None:
        """Torques act during the next :meth:`step` only."""

    @abstractmethod
    def step(self) -> None: ...

    @abstractmethod
    def collision_shapes(self) -> list[LinkShape]:
        """The character's collision shapes (what touches the ground), for viewers."""

    @abstractmethod
    def throw_ball(self, pos_world: np.ndarray, vel_world: np.ndarray, mass_kg: float = 0.43,
                   radius_m: float = 0.11) -> int:
        """Spawn a football at ``pos_world`` [m] moving at ``vel_world`` [m/s] (a scripted disturbance); its id."""

    @abstractmethod
    def body_position(self, body: int) -> np.ndarray:
        """World position [m] of a body the backend spawned (a ball)."""

    @abstractmethod
    def close(self) -> None: ...

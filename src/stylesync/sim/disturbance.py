"""Scripted disturbances: the only outside bodies that may act on the character (a football, Sec. 7.4.2)."""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import LINK_NAMES
from stylesync.model.state import CharacterState
from stylesync.sim.backend import PhysicsBackend

BALL_START_M = 1.5  # a pushed ball starts this far in front of the chest [m]
BALL_SPEED_MPS = 7.0  # a pushed ball's speed [m/s]
BALL_MASS_KG = 0.43  # a size-5 football
_CHEST_LINK = LINK_NAMES.index("chest")


def throw_ball_at_chest(backend: PhysicsBackend, state: CharacterState, speed_mps: float = BALL_SPEED_MPS,
                        start_m: float = BALL_START_M, gravity_mps2: float = 9.8) -> int:
    """A football thrown from ``start_m`` in front of the chest (along the pelvis heading) at ``speed_mps``
    horizontally, aimed up by ``g T / 2`` so that it arrives at chest height after its flight time T. Returns the
    ball's body id."""
    chest = state.link_com_world[_CHEST_LINK]
    heading = rot.yaw_from_quat(state.root_quat_wxyz)
    forward = np.array([np.cos(heading), np.sin(heading), 0.0])
    flight_s = start_m / speed_mps
    velocity = -speed_mps * forward + np.array([0.0, 0.0, 0.5 * gravity_mps2 * flight_s])
    return backend.throw_ball(chest + start_m * forward, velocity, mass_kg=BALL_MASS_KG)

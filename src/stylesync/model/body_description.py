"""The character's rigid bodies as the physics engine holds them: plain values from which ``character_model.py``
builds the Pinocchio model, so that the model and the engine simulate the same body.

Frames follow the engine's conventions, stated per field. Poses are (position [m], orientation quaternion wxyz).
The base's frame here is its *inertial* frame (the engine's base pose is that frame's pose); a link's frame is its
joint's frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np


class BodyJointKind(Enum):
    FIXED = "fixed"
    SPHERICAL = "spherical"
    REVOLUTE = "revolute"


@dataclass(frozen=True)
class LinkDescription:
    """One link of the engine's multibody (the base excluded)."""

    name: str  # the link's (and its joint's) name in the engine
    parent: int  # index of the parent link in ``BodyDescription.links``, -1 for the base
    joint_kind: BodyJointKind
    joint_axis: np.ndarray  # (3,) revolute axis in the link frame (unused otherwise)
    joint_pos_in_parent_inertial: np.ndarray  # (3,) joint frame origin in the parent's inertial frame [m]
    joint_quat_in_parent_inertial_wxyz: np.ndarray  # (4,) joint frame orientation in the parent's inertial frame
    mass_kg: float
    inertia_diag_kgm2: np.ndarray  # (3,) principal moments about the COM, in the inertial frame [kg·m²]
    inertial_pos_in_link: np.ndarray  # (3,) COM in the link frame [m]
    inertial_quat_in_link_wxyz: np.ndarray  # (4,) inertial frame orientation in the link frame
    joint_limits_rad: tuple[float, float] | None = None  # a revolute joint's (lower, upper) limit, None if unlimited


@dataclass(frozen=True)
class BodyDescription:
    """The base (its inertial frame is the floating root's frame) and every link, parents before children."""

    base_mass_kg: float
    base_inertia_diag_kgm2: np.ndarray  # (3,) about the base's COM, in its inertial frame [kg·m²]
    links: tuple[LinkDescription, ...]

    def link_index(self, name: str) -> int:
        for i, link in enumerate(self.links):
            if link.name == name:
                return i
        raise KeyError(f"no link '{name}' in the body; links: {', '.join(li.name for li in self.links)}")

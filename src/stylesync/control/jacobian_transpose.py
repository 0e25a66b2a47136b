"""Jacobian-transpose mapping of world forces and moments to joint torques (Eq. 14, 17).

For a force f [N] at a world point p carried by joint j (origin o_j), the geometric Jacobian column of a hinge
with unit world axis a is ``a × (p - o_j)``, so ``J^T f = a · ((p - o_j) × f)``; a ball joint has three such
columns along its child frame's axes, so ``J^T f = R_child^T ((p - o_j) × f)`` in the child frame, which is the
frame PyBullet applies ball-joint torques in. A joint torque acts +τ on the child link and -τ on the parent.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import JOINTS, LINK_NAMES, Q_WORLD_MODEL, JointKind
from stylesync.model.state import CharacterState

_R_WORLD_MODEL = rot.matrix_from_quat(Q_WORLD_MODEL)
_CHILD_LINK = np.array([LINK_NAMES.index(j.name) for j in JOINTS])
_IS_BALL = np.array([j.kind is JointKind.BALL for j in JOINTS])
_HINGE_AXIS_MODEL = np.array([j.axis_in_model for j in JOINTS])


class JointFrames:
    """World rotations (model axes) and origins of every joint's child link at one instant."""

    def __init__(self, state: CharacterState):
        self.origin = state.link_origin_world[_CHILD_LINK]  # (n_joints, 3)
        # (n_joints, 3, 3) child link frame (model axes) in world
        self.R = rot.batch_matrix_from_quat(state.link_quat_wxyz[_CHILD_LINK]) @ _R_WORLD_MODEL

    def torque_from_moment(self, moment_world: np.ndarray) -> np.ndarray:
        """Joint-torque layout (n_joints, 3) of world moments (n_joints, 3) [N·m] applied at each joint."""
        local = np.einsum("nji,nj->ni", self.R, moment_world)  # R^T m per joint
        out = np.zeros_like(local)
        out[_IS_BALL] = local[_IS_BALL]
        hinge = ~_IS_BALL
        out[hinge, 0] = np.einsum("ni,ni->n", local[hinge], _HINGE_AXIS_MODEL[hinge])
        return out

    def moment_of_force(self, joint_ids: np.ndarray, point_world: np.ndarray, force_world: np.ndarray) -> np.ndarray:
        """(n_joints, 3) moments (p - o_j) × f for the listed joints, zero elsewhere."""
        m = np.zeros((len(JOINTS), 3))
        r = point_world[None, :] - self.origin[joint_ids]
        m[joint_ids] = rot.cross(r, force_world[None, :])
        return m

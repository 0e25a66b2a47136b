"""Geometric Jacobians of the floating character in the generalised-velocity layout of ``sim.character``.

Layout (N_DOFS): the root's linear velocity (world, of the pelvis frame origin) and angular velocity (world), then
each joint's DOFs (ball: angular velocity about the child frame's three model axes; hinge: the rate about its
axis). This is the layout of ``PhysicsBackend.joint_space_inertia``, so ``J^T f`` of this module and the mass
matrix act on the same coordinates. A point p on link i moves with

    v_p = v_root + ω_root × (p - o_root) + Σ_{DOF d above i} a_d × (p - o_d) q̇_d ,   ω_i = ω_root + Σ a_d q̇_d

with a_d the DOF's world axis and o_d its joint's origin.
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.model.state import CharacterState
from stylesync.model.character import (
    JOINT_DOF_COUNT,
    JOINTS,
    LINK_NAMES,
    N_DOFS,
    N_JOINT_DOFS,
    ROOT_DOFS,
    JointKind,
    subtree_links,
)

DOF_JOINT = np.array([k for k in range(len(JOINTS)) for _ in range(JOINT_DOF_COUNT[k])])  # joint of each DOF
_DOF_AXIS = np.array([a for k in range(len(JOINTS)) for a in range(JOINT_DOF_COUNT[k])])
_DOF_IS_BALL = np.array([JOINTS[k].kind is JointKind.BALL for k in DOF_JOINT])
_HINGE_AXIS_MODEL = np.array([JOINTS[k].axis_in_model for k in DOF_JOINT])
# MOVES[i, d]: DOF d moves link i (link i is in the subtree of DOF d's joint).
MOVES = np.zeros((len(LINK_NAMES), N_JOINT_DOFS), dtype=bool)
for _d, _k in enumerate(DOF_JOINT):
    MOVES[subtree_links(JOINTS[_k].name), _d] = True
_MOVED_BY = MOVES.T.astype(float)  # (N_JOINT_DOFS, n_links) for the subtree sums


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


# (n_links, 3 + N_JOINT_DOFS): 1 where a rotational column (root ω x, y, z, then the joint DOFs) moves the link.
_COLUMN_MOVES = np.hstack([np.ones((len(LINK_NAMES), 3)), MOVES.astype(float)])
_EYE3 = np.eye(3)
_SKEW_OF = np.array([_skew(e).reshape(9) for e in _EYE3])  # (3, 9): a @ _SKEW_OF is [a]× flattened (linear in a)


class FloatingJacobians:
    """The DOF axes and origins of one instant; Jacobians of points, of the COM and the gravity force."""

    def __init__(self, state: CharacterState, frames: JointFrames):
        R = frames.R[DOF_JOINT]  # (N_JOINT_DOFS, 3, 3) child frames (model axes) in world
        axes = np.where(_DOF_IS_BALL[:, None], R[np.arange(N_JOINT_DOFS), :, _DOF_AXIS],
                        np.einsum("dij,dj->di", R, _HINGE_AXIS_MODEL))
        self.axis_world = axes  # (N_JOINT_DOFS, 3)
        self.origin_world = frames.origin[DOF_JOINT]  # (N_JOINT_DOFS, 3)
        self.root_world = np.asarray(state.root_pos_world, dtype=float)
        # Every rotational column (the root's angular velocity about x, y, z, then the joint DOFs) is an axis a
        # about a point o: its skew matrices stacked by rows (3 K, 3) and its a × o (K, 3), for points_linear.
        a = np.empty((3 + N_JOINT_DOFS, 3))
        a[:3], a[3:] = _EYE3, axes
        o = np.empty((3 + N_JOINT_DOFS, 3))
        o[:3], o[3:] = self.root_world, self.origin_world
        skew = (a @ _SKEW_OF).reshape(-1, 3, 3)
        self._skew_rows = skew.reshape(-1, 3)
        self._rot_axes = a
        self._a_cross_o = rot.cross(a, o)

    def point_linear(self, link: int, p_world: np.ndarray) -> np.ndarray:
        """(3, N_DOFS) Jacobian of the world velocity of point ``p_world`` fixed on link ``link``."""
        return self.points_linear(link, np.asarray(p_world, dtype=float)[None, :])[0]

    def points_linear(self, link: int, p_world: np.ndarray) -> np.ndarray:
        """(n, 3, N_DOFS) Jacobians of the world velocities of points ``p_world`` (n, 3) fixed on link ``link``."""
        n = p_world.shape[0]
        # a × (p - o) = [a]× p - a × o for every rotational column at once, those not moving the link zeroed.
        rot_cols = (p_world @ self._skew_rows.T).reshape(n, -1, 3) - self._a_cross_o
        j = np.empty((n, 3, N_DOFS))
        j[:, :, :3] = _EYE3
        j[:, :, 3:] = (rot_cols * _COLUMN_MOVES[link][None, :, None]).transpose(0, 2, 1)
        return j

    def angular(self, link: int) -> np.ndarray:
        """(3, N_DOFS) Jacobian of link ``link``'s world angular velocity."""
        j = np.zeros((3, N_DOFS))
        j[:, 3:] = self._rot_axes.T * _COLUMN_MOVES[link]
        return j

    def gravity_force(self, link_com_world: np.ndarray, link_mass_kg: np.ndarray, gravity_mps2: float) -> np.ndarray:
        """(N_DOFS,) generalised force of gravity's reaction, ``mass_weighted_linear(...)^T (0, 0, g)`` [N, N·m],
        without forming the Jacobian: for a vertical g only its third row is needed."""
        m_total = link_mass_kg.sum()
        r = link_mass_kg @ link_com_world / m_total - self.root_world
        m_sub = _MOVED_BY @ link_mass_kg
        lever = _MOVED_BY @ (link_mass_kg[:, None] * link_com_world) - m_sub[:, None] * self.origin_world
        out = np.empty(N_DOFS)
        out[:3] = (0.0, 0.0, m_total * gravity_mps2)
        out[3:6] = (m_total * gravity_mps2 * r[1], -m_total * gravity_mps2 * r[0], 0.0)  # m r × g ẑ
        a = self.axis_world
        out[ROOT_DOFS:] = gravity_mps2 * (a[:, 0] * lever[:, 1] - a[:, 1] * lever[:, 0])  # (a × L)_z g
        return out

    def mass_weighted_linear(self, link_com_world: np.ndarray, link_mass_kg: np.ndarray) -> np.ndarray:
        """(3, N_DOFS) Σ_i m_i J_i(c_i): the Jacobian of the linear momentum [kg]. Divided by the total mass it is
        the COM Jacobian; its transpose times the gravity vector is the generalised gravity force."""
        m_total = link_mass_kg.sum()
        com = link_mass_kg @ link_com_world / m_total
        j = np.zeros((3, N_DOFS))
        j[:, :3] = m_total * np.eye(3)
        j[:, 3:6] = -m_total * _skew(com - self.root_world)
        # Σ_i m_i a_d × (c_i - o_d) over the links DOF d moves = a_d × (Σ m_i c_i - M_d o_d)
        m_sub = _MOVED_BY @ link_mass_kg  # (N_JOINT_DOFS,)
        mc_sub = _MOVED_BY @ (link_mass_kg[:, None] * link_com_world)  # (N_JOINT_DOFS, 3)
        j[:, ROOT_DOFS:] = rot.cross(self.axis_world, mc_sub - m_sub[:, None] * self.origin_world).T
        return j

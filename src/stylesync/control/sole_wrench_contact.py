"""A sole's contact as one wrench inside its contact wrench cone (Caron, Pham and Nakamura, "Stability of surface
contacts for humanoid robots: closed-form formulae of the contact wrench cone for rectangular support areas",
ICRA 2015).

The corner pyramids of contacts.py span a cone of wrenches at the sole's centre, ``U w <= 0``: friction on the
resultant force, the centre of pressure inside the sole, and the torsion about the normal within what the corners'
friction can give. The paper gives its 16 rows in closed form for square pyramids; ours have their edges along the
sole's axes, and the cone's 32 rows are found once from the generators (:func:`contact_wrench_cone`). The variables
are the six components of the wrench ``w = (f, τ)`` at the sole's centre in world axes, instead of 16 magnitudes λ:
the QP has 10 variables fewer per sole, and the active set its solver carries from tick to tick holds only the faces
the wrench lies on instead of every unloaded pyramid edge (docs/decisions.md, "The control tick on the model and the
QP: where the time goes").

The pyramids turn with the sole (about the vertical, for a flat foot): with contacts.py's they keep the world's
axes. The regularisation is the corner forces' one, ``ε |λ|²`` for the least-norm λ that gives ``w``:
``ε wᵀ (G Gᵀ)⁻¹ w`` with ``G`` (6, 16) the unit forces' wrenches. It is the same as contacts.py's while every λ of
that least-norm solution is positive, and smaller near the cone's faces, where contacts.py's λ >= 0 bind.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.spatial import ConvexHull

from stylesync.control.contacts import INFINITY, SOLE_CORNERS_IN_SOLE, SoleContactBase, pyramid_edges

WRENCH_SIZE = 6


def contact_wrench_cone(generators: np.ndarray) -> np.ndarray:
    """(k, 6) U with ``U w <= 0`` exactly the cone spanned by the columns of ``generators`` (6, m), each with a
    positive normal force (row 2): the facets of the generators' section at unit normal force, a 5-dimensional
    polytope (its convex hull by Qhull), each ``a·p + b <= 0`` read as ``a·(w without f_z) + b f_z <= 0``.
    For a rectangle's four corner pyramids with their edges along its axes, 32 rows."""
    g = np.asarray(generators, dtype=float)
    section = np.delete(g / g[2], 2, axis=0).T  # (m, 5): each generator scaled to f_z = 1, without f_z
    hull = ConvexHull(section)
    rows = np.insert(hull.equations[:, :5], 2, hull.equations[:, 5], axis=1)  # (facets, 6)
    rows /= np.linalg.norm(rows, axis=1, keepdims=True)
    return np.unique(np.round(rows, 12), axis=0)  # Qhull splits a facet into simplices: one row each


def corner_wrench_generators(edges: np.ndarray, corners_in_sole: np.ndarray) -> np.ndarray:
    """(6, 16) G: the wrench at the sole's centre, in its axes, of a unit force along each of the pyramid ``edges``
    (4, 3) at each corner (4, 3) (corner by corner, edge by edge as contacts.py orders them)."""
    cols = [np.concatenate([b, np.cross(c, b)]) for c in corners_in_sole for b in edges]
    return np.array(cols).T


class SoleWrenchContact(SoleContactBase):
    """A sole whose force variables are its wrench at its centre, in world axes, inside its contact wrench cone."""

    n_forces = WRENCH_SIZE
    force_rows_constant = False  # the cone turns with the sole

    def __init__(self, side: str, friction: float, body_weight_n: float):
        super().__init__(side, body_weight_n)
        g = corner_wrench_generators(pyramid_edges(friction), SOLE_CORNERS_IN_SOLE)
        self._cone_in_sole = contact_wrench_cone(g)  # (32, 6), in the sole's axes
        self._metric_in_sole = np.linalg.inv(g @ g.T)  # (6, 6) (G Gᵀ)⁻¹
        # Per tick, after update(): the cone's rows, the normal and the metric in world axes.
        self.normal_row = np.zeros(WRENCH_SIZE)
        self.force_rows = np.zeros((len(self._cone_in_sole), WRENCH_SIZE))
        self.force_lower = np.full(len(self._cone_in_sole), -INFINITY)
        self.force_upper = np.zeros(len(self._cone_in_sole))
        self._metric_world = np.zeros((WRENCH_SIZE, WRENCH_SIZE))

    def _update_forces(self, placement: pin.SE3) -> None:
        r = placement.rotation
        self.corners_world = placement.translation + SOLE_CORNERS_IN_SOLE @ r.T
        self.generator = self.jacobian.T  # (nv, 6): the wrench at the sole's centre, world axes
        # w_sole = blockdiag(Rᵀ, Rᵀ) w_world
        self.force_rows[:, :3] = self._cone_in_sole[:, :3] @ r.T
        self.force_rows[:, 3:] = self._cone_in_sole[:, 3:] @ r.T
        self.normal_row[:3] = r[:, 2]
        rr = np.zeros((WRENCH_SIZE, WRENCH_SIZE))
        rr[:3, :3] = rr[3:, 3:] = r
        self._metric_world = rr @ self._metric_in_sole @ rr.T

    def add_regularisation(self, hessian: np.ndarray, start: int) -> None:
        """Set ``ε wᵀ (G Gᵀ)⁻¹ w`` (world axes) in the QP's ``hessian`` from variable ``start`` on."""
        hessian[start:start + WRENCH_SIZE, start:start + WRENCH_SIZE] = self.regularisation * self._metric_world

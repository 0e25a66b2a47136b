"""Sole contacts: where the ground can push the character, and how hard.

Each supporting sole passes a force at each of its four corners inside the friction cone, linearised as a 4-sided
pyramid: ``f_c = Σ_e λ_ce β_e`` with ``λ >= 0``. Forces on the corners keep the centre of pressure on the sole and
bound the torsion, so the corners' pyramids are the sole's contact wrench cone. A contact adds to the whole-body QP
its 16 force variables, its generator ``B = Σ_c J_cᵀ β`` (nv, 16) in the equations of motion, the constraint that
the sole does not move (``J q̈ + J̇ q̇ = -k_v J q̇``), a regularisation ``ε λ²`` that grows as its stance weight
falls (a foot about to lift off is unloaded first), and an upper bound on its normal force that ramps to zero
with the stance weight, so contacts are added and removed without a jump of the forces.
"""

from __future__ import annotations

import functools
from abc import ABC, abstractmethod

import numpy as np
import pinocchio as pin

from stylesync.model.character_model import SOLE_FRAMES, CharacterModel
from stylesync.model.sole import sole_corners_in_foot, sole_within_m
from stylesync.model.sole import sole_corners_world as model_sole_corners_world

SOLE_MARGIN = 0.9  # fraction of the sole's length and width the corner forces may use
FRICTION_MARGIN = 0.8  # fraction of the friction coefficient the pyramid uses
COP_MARGIN = 0.9  # fraction of the support's extent the desired horizontal force may use
MOMENTUM_ACCEL_ALLOWANCE_MPS2 = 0.5  # horizontal COM acceleration allowed beyond the pendulum's [m/s²]
REGULARISATION = 1e-4  # ε of a full-weight foot [1/N² against the tasks' squared residuals]
MIN_WEIGHT = 0.05  # a stance weight below this is treated as this (ε = REGULARISATION / weight)
# The normal-force bound: this many body weights at full contact, ramped down linearly below RAMP_WEIGHT.
MAX_NORMAL_FORCE_BODY_WEIGHTS = 3.0
RAMP_WEIGHT = 0.1
FORCES_PER_SOLE = 16  # 4 corners x 4 pyramid edges
INFINITY = 1e20  # the QP's unbounded side
# The corners the forces act at, relative to the ankle joint in the foot's canonical frame [m], (4, 3).
SOLE_CORNERS_IN_FOOT = sole_corners_in_foot(SOLE_MARGIN)
# The same relative to the sole's centre [m], (4, 3).
SOLE_CORNERS_IN_SOLE = SOLE_CORNERS_IN_FOOT - SOLE_CORNERS_IN_FOOT.mean(axis=0)
_EDGE_DIRS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


def sole_corners_world(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray) -> np.ndarray:
    """(4, 3) world positions of the corners the sole's forces act at [m]."""
    return model_sole_corners_world(ankle_world, foot_quat_wxyz, SOLE_CORNERS_IN_FOOT)


def sole_touches(ankle_world: np.ndarray, foot_quat_wxyz: np.ndarray, pressing: bool, gap_m: float) -> bool:
    """Whether a foot can be given ground forces: it presses the ground (``CharacterState.feet_pressing``), or the
    lowest corner of its sole is within ``gap_m`` of the ground (``gap_m`` > 0: a planted foot just unloaded)."""
    return pressing or (gap_m > 0 and sole_within_m(ankle_world, foot_quat_wxyz, gap_m, SOLE_CORNERS_IN_FOOT))


@functools.lru_cache(maxsize=8)
def pyramid_edges(friction: float) -> np.ndarray:
    """(4, 3) unit edges of the linearised friction cone of a flat ground (FRICTION_MARGIN of ``friction``)."""
    mu = FRICTION_MARGIN * friction
    e = np.column_stack([mu * _EDGE_DIRS, np.ones(4)])
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    e.setflags(write=False)
    return e


def feasible_horizontal_force(force_n: np.ndarray, com_world: np.ndarray, corners_world: list[np.ndarray],
                              mass_kg: float, gravity_mps2: float) -> np.ndarray:
    """The desired force (3,) [N] with its horizontal part limited to what a centre of pressure inside the support
    can give: by the linear inverted pendulum (the model of Eq. 21), m p̈ = m g / h (c - p_cop) per horizontal
    axis, with p_cop within the soles' extent on that axis, shrunk by COP_MARGIN about its middle, widened by
    MOMENTUM_ACCEL_ALLOWANCE_MPS2 (a change of angular momentum, the hip strategy, gives some force the pendulum
    does not). A larger request cannot be met by the ground; left in the momentum task, it would be traded against
    the vertical force and the moment, which lifts or tips the body."""
    out = np.array(force_n, dtype=float)
    if not corners_world:
        return out
    pts = np.concatenate(corners_world).tolist()  # Python floats: a few scalars per corner
    h = max(float(com_world[2]) - sum(p[2] for p in pts) / len(pts), 0.1)
    k = mass_kg * gravity_mps2 / h
    lo = [min(p[0] for p in pts), min(p[1] for p in pts)]
    hi = [max(p[0] for p in pts), max(p[1] for p in pts)]
    extra = mass_kg * MOMENTUM_ACCEL_ALLOWANCE_MPS2
    for ax in (0, 1):
        mid, half = 0.5 * (lo[ax] + hi[ax]), 0.5 * COP_MARGIN * (hi[ax] - lo[ax])
        c = float(com_world[ax])
        lo_f = min(k * (c - mid - half), 0.0) - extra
        hi_f = max(k * (c - mid + half), 0.0) + extra
        out[ax] = min(max(float(out[ax]), lo_f), hi_f)
    return out


class SoleContactBase(ABC):
    """One foot's sole on the ground, as the whole-body QP sees it: its kinematics at the model's state, its
    regularisation's weight and its normal force's bound, whatever its force variables.

    What the formulation reads of a contact: ``n_forces`` variables, their ``generator`` (nv, n_forces) in the
    equations of motion, ``n_rows`` constraint rows (:meth:`constraint_rows`), their regularisation
    (:meth:`add_regularisation`), the ``normal_row`` (n_forces,) that gives the normal force, and ``force_rows``
    (k, n_forces) with ``force_lower``/``force_upper`` (k,): the force variables' own inequalities, the same at every
    tick when ``force_rows_constant``. A subclass fills those from the sole's placement (:meth:`_update_forces`)."""

    n_forces: int
    n_rows = 6  # the constraint rows that keep the sole where it is (constraint_rows)
    force_rows_constant: bool
    normal_row: np.ndarray
    force_rows: np.ndarray
    force_lower: np.ndarray
    force_upper: np.ndarray

    def __init__(self, side: str, body_weight_n: float):
        self.side = side
        self.frame = SOLE_FRAMES[side]
        self.body_weight_n = body_weight_n
        self.stance_weight = 1.0  # set per tick: the share of the body this foot is meant to carry, [0, 1]
        # set per tick: the least normal force planned for this sole, as a share of the body's weight at full stance
        # weight (WholeBodyConfig.standing_sole_min_load_share) [-]
        self.min_load_share = 0.0
        # Per tick, after update(): the generator (nv, n_forces), the sole's Jacobian (6, nv), drift (6,), corners
        # (4, 3).
        self.generator = np.zeros((0, 0))
        self.jacobian = np.zeros((6, 0))
        self.drift = np.zeros(6)
        self.velocity = np.zeros(6)
        self.corners_world = np.zeros((4, 3))
        self._updated_for: tuple[int, int] | None = None  # (model, revision) of the last update

    def update(self, model: CharacterModel) -> None:
        """The sole's Jacobian, drift, velocity, corners and force variables' terms at the model's current state
        (once per model update: a second call for the same state does nothing)."""
        if self._updated_for == (id(model), model.revision):
            return
        self._updated_for = (id(model), model.revision)
        f = model.frame_id(self.frame)
        self.jacobian = model.frame_jacobian(f)
        self.drift = model.frame_drift(f)
        self.velocity = model.frame_velocity(f)
        self._update_forces(model.frame_placement(f))

    @abstractmethod
    def _update_forces(self, placement: pin.SE3) -> None:
        """``corners_world``, ``generator`` and what else of the force variables turns with the sole, from its world
        ``placement`` (``jacobian`` is current)."""

    @abstractmethod
    def add_regularisation(self, hessian: np.ndarray, start: int) -> None:
        """Set this contact's regularisation in the QP's ``hessian`` (n, n) from variable ``start`` on."""

    @property
    def regularisation(self) -> float:
        """ε of this contact's forces: larger as its stance weight falls."""
        return REGULARISATION / max(self.stance_weight, MIN_WEIGHT)

    @property
    def max_normal_force_n(self) -> float:
        """Upper bound of the normal force [N], ramped down with the stance weight below RAMP_WEIGHT."""
        return MAX_NORMAL_FORCE_BODY_WEIGHTS * self.body_weight_n * min(1.0, self.stance_weight / RAMP_WEIGHT)

    @property
    def min_normal_force_n(self) -> float:
        """Lower bound of the normal force [N]: ``min_load_share`` of the body's weight, ramped down with the stance
        weight below RAMP_WEIGHT as the upper bound is."""
        return self.min_load_share * self.body_weight_n * min(1.0, self.stance_weight / RAMP_WEIGHT)

    def constraint_rows(self, velocity_gain: float) -> tuple[np.ndarray, np.ndarray]:
        """The sole does not move: ``J q̈ = -J̇ q̇ - k_v J q̇`` (its residual velocity damped at ``velocity_gain``)."""
        return self.jacobian, -self.drift - velocity_gain * self.velocity


class SoleContact(SoleContactBase):
    """A sole whose force variables are the magnitudes λ of the unit forces along its corners' friction pyramids
    (world axes): its four corners (``corners_in_sole``, relative to the sole's centre in the foot's frame; a
    subclass may stand on fewer, toe_contact.py)."""

    corners_in_sole = SOLE_CORNERS_IN_SOLE
    n_forces = FORCES_PER_SOLE  # 4 pyramid edges per corner
    force_rows_constant = True  # λ >= 0: unit rows

    def __init__(self, side: str, friction: float, body_weight_n: float):
        super().__init__(side, body_weight_n)
        k = len(self.corners_in_sole)
        self.edges = pyramid_edges(friction)  # (4, 3)
        self.force_rows = np.eye(self.n_forces)
        self.force_lower, self.force_upper = np.zeros(self.n_forces), np.full(self.n_forces, INFINITY)
        # Normal components of the unit forces (the same at every corner): Σ_e n_e λ_e is the normal force.
        self.normal_row = np.tile(self.edges[:, 2], k)
        self._forces = np.tile(self.edges.T, k)  # (3, 4 k): the unit forces, corner by corner, edge by edge
        self.corners_world = np.zeros((k, 3))
        # The map (3 * 4 k, k corners x 3) from the corners' levers r_c, stacked, to every unit force's moment
        # r_c × β_e, (3, 4 k) flattened: corner by corner, edge by edge as in _forces.
        lever_to_moments = np.zeros((3, self.n_forces, k, 3))
        for c in range(k):
            for e, b in enumerate(self.edges):
                lever_to_moments[:, 4 * c + e, c, :] = np.cross(np.eye(3), b).T  # K r = r × b
        self._lever_to_moments = lever_to_moments.reshape(3 * self.n_forces, 3 * k)

    def _update_forces(self, placement: pin.SE3) -> None:
        levers = self.corners_in_sole @ placement.rotation.T  # (k, 3) corner - sole centre, world axes
        self.corners_world = placement.translation + levers
        # B = Σ_c J_cᵀ β_e = J_linᵀ β_e + J_angᵀ (r_c × β_e), corner by corner, edge by edge.
        moments = (self._lever_to_moments @ levers.reshape(-1)).reshape(3, self.n_forces)
        self.generator = self.jacobian[:3].T @ self._forces + self.jacobian[3:].T @ moments

    def add_regularisation(self, hessian: np.ndarray, start: int) -> None:
        """Set ``ε λ²`` on the diagonal of the QP's ``hessian`` (n, n) from variable ``start`` on."""
        n = len(hessian)
        hessian.ravel()[start * (n + 1):(start + self.n_forces) * (n + 1):n + 1] = self.regularisation

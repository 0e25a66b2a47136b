"""The whole-body QP of one control tick: tasks, contacts and limits collected into one quadratic programme.

Variables ``x = (q̈, λ)``: the joint accelerations (nv, the character's layout) and each active sole's force
variables: by default the magnitudes of its forces along its corners' friction pyramid edges (16, contacts.py), or
its wrench (6, sole_wrench_contact.py, with ``λ >= 0`` below its cone's faces ``U λ <= 0`` and ``ε |λ|²`` its
metric ``ε λᵀ (G Gᵀ)⁻¹ λ``). The problem is

    min_x  ½ Σ_tasks Σ_rows w (A q̈ - b)² + ½ Σ_contacts ε |λ|²
    s.t.   M_root q̈ + h_root = (B λ)_root                     (the floating root's six equations of motion)
           J_c q̈ + J̇_c q̇ = -k_v J_c q̇                          (each supporting sole stays where it is; a sole on
                                                                its toes turns about its toe line, toe_contact.py)
           -τ_max <= M_j q̈ + h_j - (B λ)_j <= τ_max           (joint torque limits)
           f_min(c) <= Σ n·f_c <= f_max(c)                     (each sole's normal force, ramped with its weight;
                                                                f_min 0 but where he stands still)
           λ >= 0,  q̈_lo <= q̈_hinge <= q̈_hi                  (friction pyramids; hinge limits over a horizon)

and the torques follow from the joint rows of the equations of motion, ``τ = M_j q̈ + h_j - (B λ)_j``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from stylesync.control.contacts import INFINITY, SoleContactBase
from stylesync.control.tasks.base import Task
from stylesync.model.character import JOINT_DOF_START, JOINTS, N_DOFS, ROOT_DOFS, JointKind
from stylesync.model.character_model import CharacterModel

T = TypeVar("T", bound=Task)


@dataclass
class QpProblem:
    """``min ½ xᵀ H x + gᵀ x  s.t.  A x = b,  l <= C x <= u``, with the constraints stacked in one matrix as the
    solver takes them: ``rows = [A; C]``, ``lower = [b; l]``, ``upper = [b; u]``."""

    H: np.ndarray
    g: np.ndarray
    rows: np.ndarray  # (n_eq + n_in, n): the equalities' rows, then the inequalities'
    lower: np.ndarray  # (n_eq + n_in,)
    upper: np.ndarray  # (n_eq + n_in,)
    n_eq: int
    n_forces: int

    @property
    def A(self) -> np.ndarray:  # noqa: N802 (the QP's usual names)
        return self.rows[:self.n_eq]

    @property
    def b(self) -> np.ndarray:
        return self.lower[:self.n_eq]

    @property
    def C(self) -> np.ndarray:  # noqa: N802
        return self.rows[self.n_eq:]

    @property
    def l(self) -> np.ndarray:  # noqa: E743
        return self.lower[self.n_eq:]

    @property
    def u(self) -> np.ndarray:
        return self.upper[self.n_eq:]


@dataclass(frozen=True)
class RowBound:
    """An inequality of one tick on the joint accelerations: ``lower <= row · q̈ <= upper`` (row (nv,), the
    character's DOF layout)."""

    row: np.ndarray
    lower: float
    upper: float


@dataclass(frozen=True)
class HingeLimit:
    dof: int  # index in the character's DOF layout
    lower_rad: float
    upper_rad: float


def hinge_limits(limits_by_joint: dict[str, tuple[float, float]]) -> tuple[HingeLimit, ...]:
    """The hinges' position limits in the character's DOF layout (from ``BodyDescription`` link limits)."""
    out = []
    for k, spec in enumerate(JOINTS):
        if spec.kind is JointKind.HINGE and spec.name in limits_by_joint:
            lo, hi = limits_by_joint[spec.name]
            out.append(HingeLimit(ROOT_DOFS + JOINT_DOF_START[k], lo, hi))
    return tuple(out)


class WholeBodyFormulation:
    """Collects tasks, contacts and limits; builds the QP of one tick and turns its solution into torques."""

    def __init__(self, torque_limit_nm: np.ndarray, limits: tuple[HingeLimit, ...], contact_velocity_gain: float,
                 limit_horizon_s: float):
        self.tasks: list[Task] = []
        self.torque_limit_nm = np.asarray(torque_limit_nm, dtype=float)  # (n_joint_dofs,)
        self.limits = limits
        self._limit_dofs = np.array([lim.dof for lim in limits], dtype=int)
        self._limit_rows = np.arange(len(limits))
        self._limit_lower = np.array([lim.lower_rad for lim in limits])  # [rad]
        self._limit_upper = np.array([lim.upper_rad for lim in limits])  # [rad]
        self.contact_velocity_gain = contact_velocity_gain  # [1/s]
        self.limit_horizon_s = limit_horizon_s  # [s]
        self._templates: dict[tuple[type, ...], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}  # by the soles

    def add_task(self, task: T) -> T:
        self.tasks.append(task)
        return task

    def task(self, name: str) -> Task:
        for t in self.tasks:
            if t.name == name:
                return t
        raise KeyError(f"no task '{name}'; tasks: {', '.join(t.name for t in self.tasks)}")

    def build(self, model: CharacterModel, contacts: Sequence[SoleContactBase],
              bounds: Sequence[RowBound] = ()) -> QpProblem:
        """The QP of this tick; ``bounds``: inequalities on q̈ of this tick alone, put before the hinges' limits."""
        nv = N_DOFS
        n_c = len(contacts)
        n_f = sum(c.n_forces for c in contacts)
        n = nv + n_f
        h_mat = np.zeros((n, n))
        g = np.zeros(n)
        for task in self.tasks:
            if not task.active:
                continue
            r = task.rows(model)
            if r.jacobian is None:  # rows on single DOFs: a diagonal
                if isinstance(r.dofs, slice):  # a range of DOFs: a strided view of the diagonal
                    h_mat.ravel()[r.dofs.start * (n + 1):r.dofs.stop * (n + 1):n + 1] += r.weight
                else:
                    h_mat[r.dofs, r.dofs] += r.weight
                g[r.dofs] -= r.weight * r.target
                continue
            wj = r.weight[:, None] * r.jacobian
            h_mat[:nv, :nv] += r.jacobian.T @ wj
            g[:nv] -= wj.T @ r.target
        # Equalities: the root's equations of motion, then each sole's 6 acceleration rows. Then the inequalities:
        # joint torques, each sole's normal force, each sole's own force rows (the pyramids' λ >= 0 or the wrench
        # cone), the hinges' limits. What does not change from one tick to the next (the pyramids' and the hinges'
        # unit rows, the bounds of the force rows) comes from a template.
        n_eq = ROOT_DOFS + sum(c.n_rows for c in contacts)
        n_tau = nv - ROOT_DOFS
        key = tuple(type(c) for c in contacts)
        template = self._templates.get(key)
        if template is None:
            template = self._templates[key] = self._template(contacts)
        rows, lower, upper = (a.copy() for a in template)
        m, h = model.mass_matrix, model.bias_forces
        rows[:ROOT_DOFS, :nv] = m[:ROOT_DOFS]
        lower[:ROOT_DOFS] = -h[:ROOT_DOFS]
        tau_rows = slice(n_eq, n_eq + n_tau)
        rows[tau_rows, :nv] = m[ROOT_DOFS:]
        start, force_row, eq_row = nv, n_eq + n_tau + n_c, ROOT_DOFS
        for i, c in enumerate(contacts):
            c.update(model)
            sl = slice(start, start + c.n_forces)
            c.add_regularisation(h_mat, start)
            rows[:ROOT_DOFS, sl] = -c.generator[:ROOT_DOFS]  # -B of the equations of motion
            rows[tau_rows, sl] = -c.generator[ROOT_DOFS:]
            jac, acc = c.constraint_rows(self.contact_velocity_gain)
            rows[eq_row:eq_row + c.n_rows, :nv] = jac
            lower[eq_row:eq_row + c.n_rows] = acc
            eq_row += c.n_rows
            normal = n_eq + n_tau + i
            rows[normal, sl] = c.normal_row
            upper[normal] = c.max_normal_force_n
            if c.min_load_share > 0.0:
                lower[normal] = c.min_normal_force_n
            k = len(c.force_rows)
            if not c.force_rows_constant:
                rows[force_row:force_row + k, sl] = c.force_rows
            start, force_row = start + c.n_forces, force_row + k
        upper[:n_eq] = lower[:n_eq]
        lower[tau_rows] = -self.torque_limit_nm - h[ROOT_DOFS:]
        upper[tau_rows] = self.torque_limit_nm - h[ROOT_DOFS:]
        if self.limits:  # q + q̇ T + ½ q̈ T² within the limits
            t = self.limit_horizon_s
            q, qd = model.joint_positions(self._limit_dofs), model.v[self._limit_dofs]
            first = len(rows) - len(self.limits)
            lower[first:] = np.minimum(2.0 * (self._limit_lower - q - qd * t) / (t * t), 0.0)
            upper[first:] = np.maximum(2.0 * (self._limit_upper - q - qd * t) / (t * t), 0.0)
        if bounds:
            at = len(rows) - len(self.limits)
            extra = np.zeros((len(bounds), n))
            for i, b in enumerate(bounds):
                extra[i, :nv] = b.row
            rows = np.insert(rows, at, extra, axis=0)
            lower = np.insert(lower, at, [b.lower for b in bounds])
            upper = np.insert(upper, at, [b.upper for b in bounds])
        return QpProblem(h_mat, g, rows, lower, upper, n_eq, n_f)

    def _template(self, contacts: Sequence[SoleContactBase]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The constraint rows and bounds of a QP with these soles that are the same at every tick: the contacts'
        constant force rows (the pyramids' λ >= 0) and their force rows' bounds, the normal forces' lower bound 0
        and the hinges' unit rows; the rest is zero."""
        nv, n_c = N_DOFS, len(contacts)
        n_f = sum(c.n_forces for c in contacts)
        n_eq = ROOT_DOFS + sum(c.n_rows for c in contacts)
        n_force_rows = sum(len(c.force_rows) for c in contacts)
        n_in = nv - ROOT_DOFS + n_c + n_force_rows + len(self.limits)
        rows = np.zeros((n_eq + n_in, nv + n_f))
        lower, upper = np.zeros(n_eq + n_in), np.zeros(n_eq + n_in)
        row, col = n_eq + nv - ROOT_DOFS + n_c, nv  # the normal-force rows (lower bound 0) come before this
        for c in contacts:
            k = len(c.force_rows)
            if c.force_rows_constant:
                rows[row:row + k, col:col + c.n_forces] = c.force_rows
            lower[row:row + k], upper[row:row + k] = c.force_lower, c.force_upper
            row, col = row + k, col + c.n_forces
        rows[row + self._limit_rows, self._limit_dofs] = 1.0
        return rows, lower, upper

    def with_limits_opened(self, problem: QpProblem) -> QpProblem:
        """A copy of ``problem`` without its joint torque limits and its hinges' limit horizon (those rows bounded by
        ±INFINITY): what may give way when the problem has no feasible point. The root's equations of motion, the
        soles' contact rows and their forces' bounds stay."""
        lower, upper = problem.lower.copy(), problem.upper.copy()
        n_tau = N_DOFS - ROOT_DOFS
        lower[problem.n_eq:problem.n_eq + n_tau], upper[problem.n_eq:problem.n_eq + n_tau] = -INFINITY, INFINITY
        if self.limits:
            lower[-len(self.limits):], upper[-len(self.limits):] = -INFINITY, INFINITY
        return QpProblem(problem.H, problem.g, problem.rows, lower, upper, problem.n_eq, problem.n_forces)

    @staticmethod
    def torques(model: CharacterModel, problem: QpProblem, x: np.ndarray) -> np.ndarray:
        """(n_joint_dofs,) joint torques of a solution: the joint rows of the equations of motion [N·m]."""
        return problem.C[:N_DOFS - ROOT_DOFS] @ x + model.bias_forces[ROOT_DOFS:]

"""The whole-body QP of one control tick: tasks, contacts and limits collected into one quadratic programme.

Variables ``x = (q̈, λ)``: the joint accelerations (nv, the character's layout) and the magnitudes of the contact
forces along the friction pyramids' edges (16 per active sole). The problem is

    min_x  ½ Σ_tasks Σ_rows w (A q̈ - b)² + ½ Σ_contacts ε |λ|²
    s.t.   M_root q̈ + h_root = (B λ)_root                     (the floating root's six equations of motion)
           J_c q̈ + J̇_c q̇ = -k_v J_c q̇                          (each supporting sole stays where it is)
           -τ_max <= M_j q̈ + h_j - (B λ)_j <= τ_max           (joint torque limits)
           0 <= Σ n·f_c <= f_max(c)                            (each sole's normal force, ramped with its weight)
           λ >= 0,  q̈_lo <= q̈_hinge <= q̈_hi                  (friction pyramids; hinge limits over a horizon)

and the torques follow from the joint rows of the equations of motion, ``τ = M_j q̈ + h_j - (B λ)_j``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from stylesync.control.contacts import FORCES_PER_SOLE, SoleContact
from stylesync.control.tasks.base import Task
from stylesync.model.character import JOINT_DOF_START, JOINTS, N_DOFS, ROOT_DOFS, JointKind
from stylesync.model.character_model import CharacterModel

INFINITY = 1e20  # ProxQP's unbounded side
T = TypeVar("T", bound=Task)


@dataclass
class QpProblem:
    """``min ½ xᵀ H x + gᵀ x  s.t.  A x = b,  l <= C x <= u``."""

    H: np.ndarray
    g: np.ndarray
    A: np.ndarray
    b: np.ndarray
    C: np.ndarray
    l: np.ndarray
    u: np.ndarray
    n_forces: int


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
        self.contact_velocity_gain = contact_velocity_gain  # [1/s]
        self.limit_horizon_s = limit_horizon_s  # [s]

    def add_task(self, task: T) -> T:
        self.tasks.append(task)
        return task

    def task(self, name: str) -> Task:
        for t in self.tasks:
            if t.name == name:
                return t
        raise KeyError(f"no task '{name}'; tasks: {', '.join(t.name for t in self.tasks)}")

    def build(self, model: CharacterModel, contacts: list[SoleContact]) -> QpProblem:
        nv = N_DOFS
        n_f = FORCES_PER_SOLE * len(contacts)
        n = nv + n_f
        h_mat = np.zeros((n, n))
        g = np.zeros(n)
        for task in self.tasks:
            if not task.active:
                continue
            r = task.rows(model)
            if r.jacobian is None:  # rows on single DOFs: a diagonal
                h_mat[r.dofs, r.dofs] += r.weight
                g[r.dofs] -= r.weight * r.target
                continue
            wj = r.weight[:, None] * r.jacobian
            h_mat[:nv, :nv] += r.jacobian.T @ wj
            g[:nv] -= wj.T @ r.target
        gen = np.zeros((nv, n_f))  # B
        for i, c in enumerate(contacts):
            c.update(model)
            sl = slice(nv + FORCES_PER_SOLE * i, nv + FORCES_PER_SOLE * (i + 1))
            h_mat[sl, sl].flat[::FORCES_PER_SOLE + 1] = c.regularisation
            gen[:, sl.start - nv:sl.stop - nv] = c.generator
        m, h = model.mass_matrix, model.bias_forces
        # Equalities: the root's equations of motion, then each sole's 6 acceleration rows.
        a_eq = np.zeros((ROOT_DOFS + 6 * len(contacts), n))
        b_eq = np.zeros(len(a_eq))
        a_eq[:ROOT_DOFS, :nv] = m[:ROOT_DOFS]
        a_eq[:ROOT_DOFS, nv:] = -gen[:ROOT_DOFS]
        b_eq[:ROOT_DOFS] = -h[:ROOT_DOFS]
        for i, c in enumerate(contacts):
            jac, acc = c.constraint_rows(self.contact_velocity_gain)
            a_eq[ROOT_DOFS + 6 * i:ROOT_DOFS + 6 * (i + 1), :nv] = jac
            b_eq[ROOT_DOFS + 6 * i:ROOT_DOFS + 6 * (i + 1)] = acc
        # Inequalities: joint torques, each sole's normal force, the pyramids' λ >= 0, the hinges' limits.
        n_tau = nv - ROOT_DOFS
        n_in = n_tau + len(contacts) + n_f + len(self.limits)
        c_in = np.zeros((n_in, n))
        lower = np.empty(n_in)
        upper = np.empty(n_in)
        c_in[:n_tau, :nv] = m[ROOT_DOFS:]
        c_in[:n_tau, nv:] = -gen[ROOT_DOFS:]
        lower[:n_tau] = -self.torque_limit_nm - h[ROOT_DOFS:]
        upper[:n_tau] = self.torque_limit_nm - h[ROOT_DOFS:]
        row = n_tau
        for i, c in enumerate(contacts):
            c_in[row, nv + FORCES_PER_SOLE * i:nv + FORCES_PER_SOLE * (i + 1)] = c.normal_row
            lower[row], upper[row] = 0.0, c.max_normal_force_n
            row += 1
        c_in[row:row + n_f, nv:].flat[::n_f + 1] = 1.0
        lower[row:row + n_f], upper[row:row + n_f] = 0.0, INFINITY
        row += n_f
        t = self.limit_horizon_s
        for lim in self.limits:  # q + q̇ T + ½ q̈ T² within the limits
            q, qd = model.joint_position(lim.dof), model.v[lim.dof]
            c_in[row, lim.dof] = 1.0
            lower[row] = min(2.0 * (lim.lower_rad - q - qd * t) / (t * t), 0.0)
            upper[row] = max(2.0 * (lim.upper_rad - q - qd * t) / (t * t), 0.0)
            row += 1
        return QpProblem(h_mat, g, a_eq, b_eq, c_in, lower, upper, n_f)

    @staticmethod
    def torques(model: CharacterModel, problem: QpProblem, x: np.ndarray) -> np.ndarray:
        """(n_joint_dofs,) joint torques of a solution: the joint rows of the equations of motion [N·m]."""
        nv = N_DOFS
        return problem.C[:nv - ROOT_DOFS] @ x + model.bias_forces[ROOT_DOFS:]

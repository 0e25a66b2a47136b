"""Contact-consistent inverse dynamics of the floating character: joint torques that give the chosen ground forces.

With the ground forces fixed (contact_forces.py), the equations of motion ``M q̈ + h = S^T τ + Q_c`` split into the
root's six unactuated rows, which fix how the whole body accelerates under those forces, and the joint rows, which
give the torques. The accelerations are the ones closest to the desired ones (joint PD, Eq. 13 in acceleration
form) that obey the root's rows and keep each supporting foot where it is:

    min Σ w_d (q̈_d - q̈_d*)²   s.t.   M_root q̈ = Q_c,root - h_root ,   J_c q̈ = -k_c J_c q̇

(a small KKT system), and then ``τ = (M q̈ + h - Q_c)_joints``. h holds gravity only: the velocity-product terms
of this character at teleoperation speeds are a few N·m against the hundreds gravity asks, and are left to the
feedback, as Eq. 14-15 do.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import lapack
from scipy.optimize import nnls

from stylesync.control.nnls import nnls_gram
from stylesync.model.character import N_DOFS, ROOT_DOFS

_EYE_ROOT = np.eye(ROOT_DOFS)


def joint_torques(mass_matrix: np.ndarray, bias_force: np.ndarray, contact_force: np.ndarray,
                  qdd: np.ndarray) -> np.ndarray:
    """(N_JOINT_DOFS,) torques [N·m] of ``M q̈ + h = S^T τ + Q_c``."""
    return (mass_matrix @ qdd + bias_force - contact_force)[ROOT_DOFS:]


def solve_with_contact_forces(mass_matrix: np.ndarray, bias_force: np.ndarray, force_basis: np.ndarray,
                              contact_jacobian: np.ndarray, contact_accel: np.ndarray, qdd_desired: np.ndarray,
                              weights: np.ndarray, wrench_matrix: np.ndarray, wrench_desired: np.ndarray,
                              wrench_row_weights: np.ndarray, force_regularisation: np.ndarray,
                              task_jacobian: np.ndarray, task_accel: np.ndarray, task_weight: float,
                              free_start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q̈ (N_DOFS,) and the contact-force magnitudes λ >= 0 of one problem over both:

        min Σ w_d (q̈_d - q̈_d*)² + w_t |J_t q̈ - a_t|² + |W_f (A λ - F*)|² + Σ ε_i λ_i²
        s.t. M_root q̈ = (B λ)_root - h_root ,  J_c q̈ = a_c ,  λ >= 0

    B (N_DOFS, n_λ) maps λ to generalised forces, A (6, n_λ) to the wrench about the COM. For a fixed λ the
    accelerations are affine in λ (the KKT system of :func:`solve_accelerations`), q̈ = r + P λ; substituted, the
    problem is a non-negative least squares in λ alone. Joint tracking and the desired wrench are thereby traded
    against each other in one objective: the momentum the soles cannot give is not forced onto the arms.

    ``free_start``: the mask of positive λ of a previous solution of a problem of the same layout, to warm-start
    the non-negative least squares (nnls.py); None solves it from scratch. Returns q̈, λ and the mask of λ > 0.
    """
    k = ROOT_DOFS + contact_jacobian.shape[0]  # equality rows: the root's, then the contacts'
    n = N_DOFS + k
    kkt = np.zeros((n, n))
    kkt.flat[:N_DOFS * (n + 1):n + 1] = weights  # the Hessian's diagonal
    if task_jacobian.shape[0]:
        kkt[:N_DOFS, :N_DOFS] += task_weight * task_jacobian.T @ task_jacobian
    kkt[N_DOFS:N_DOFS + ROOT_DOFS, :N_DOFS] = mass_matrix[:ROOT_DOFS]
    kkt[N_DOFS + ROOT_DOFS:, :N_DOFS] = contact_jacobian
    kkt[:N_DOFS, N_DOFS:] = kkt[N_DOFS:, :N_DOFS].T
    n_lam = force_basis.shape[1]
    # Right-hand sides: the one of λ = 0, and a unit one per root row. λ enters only through the root rows,
    # (B λ)_root, so P = K⁻¹ [0; B_root; 0] is the solutions of the unit sides times B_root: 7 sides to solve
    # instead of 1 + n_λ.
    rhs = np.zeros((N_DOFS + k, 1 + ROOT_DOFS))
    rhs[:N_DOFS, 0] = weights * qdd_desired
    if task_jacobian.shape[0]:
        rhs[:N_DOFS, 0] += task_weight * task_jacobian.T @ task_accel
    rhs[N_DOFS:N_DOFS + ROOT_DOFS, 0] = -bias_force[:ROOT_DOFS]
    rhs[N_DOFS + ROOT_DOFS:, 0] = contact_accel
    rhs[N_DOFS:N_DOFS + ROOT_DOFS, 1:] = _EYE_ROOT
    *_, sol, info = lapack.dgesv(kkt, rhs)  # LAPACK's LU solve without numpy's wrapper (a control-tick cost)
    if info != 0:  # singular (or a bad argument): the least-squares solution
        sol = np.linalg.lstsq(kkt, rhs, rcond=None)[0]
    r, p = sol[:N_DOFS, 0], sol[:N_DOFS, 1:] @ force_basis[:ROOT_DOFS]
    if n_lam == 0:  # no support: the accelerations follow from the root's rows alone
        return r, np.zeros(0), np.zeros(0, dtype=bool)
    sw = np.sqrt(weights)
    st = np.sqrt(task_weight)
    # The residual rows without the regularisation's (a diagonal, added below as rows or to the Gram matrix).
    n_task = task_jacobian.shape[0]
    a_rows = np.empty((N_DOFS + n_task + len(wrench_desired), n_lam))
    b_rows = np.empty(len(a_rows))
    a_rows[:N_DOFS] = sw[:, None] * p
    b_rows[:N_DOFS] = sw * (qdd_desired - r)
    if n_task:
        a_rows[N_DOFS:N_DOFS + n_task] = st * task_jacobian @ p
        b_rows[N_DOFS:N_DOFS + n_task] = st * (task_accel - task_jacobian @ r)
    a_rows[N_DOFS + n_task:] = wrench_row_weights[:, None] * wrench_matrix
    b_rows[N_DOFS + n_task:] = wrench_row_weights * wrench_desired
    if free_start is None or free_start.shape != (n_lam,):
        lam, _ = nnls(np.vstack([a_rows, np.diag(np.sqrt(force_regularisation))]),
                      np.concatenate([b_rows, np.zeros(n_lam)]), maxiter=50 * n_lam)
        free = lam > 0.0
    else:
        gram = a_rows.T @ a_rows
        gram.flat[::n_lam + 1] += force_regularisation  # the diagonal
        lam, free = nnls_gram(gram, a_rows.T @ b_rows, free_start)
    return r + p @ lam, lam, free

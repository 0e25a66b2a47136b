"""Non-negative least squares by the Lawson-Hanson active-set method on the normal equations, warm-started.

    min |A x - b|²  s.t.  x >= 0 ,  given G = A^T A (positive definite) and c = A^T b.

The contact forces of successive control ticks (inverse_dynamics.py) come from nearly the same problem: the set
of sole-corner forces that are zero changes rarely. Started from the previous tick's set of free (positive)
variables, the method usually ends after one solve of the free block and one check of the gradient, where a cold
start adds the variables one by one. With G positive definite the problem is strictly convex: the minimiser is
unique, and warm and cold starts reach the same x (to rounding).

Lawson & Hanson, *Solving Least Squares Problems* (1974), Ch. 23; on the normal equations as Bro & De Jong,
"A fast non-negativity-constrained least squares algorithm", J. Chemometrics 11 (1997).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import lapack

GRADIENT_TOL = 1e-10  # a zero variable whose gradient is below this times max|c| stays zero


def _solve_free(gram: np.ndarray, rhs: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The unconstrained minimiser on the free variables (others zero)."""
    z = np.zeros(len(rhs))
    idx = free.nonzero()[0]
    if idx.size:
        block = gram.take(idx, 0).take(idx, 1)
        _, sol, info = lapack.dposv(block, rhs.take(idx))
        if info != 0:  # not positive definite to working precision: the least-squares solution
            sol = np.linalg.lstsq(block, rhs.take(idx), rcond=None)[0]
        z[idx] = sol
    return z


def nnls_gram(gram: np.ndarray, rhs: np.ndarray, free_start: np.ndarray | None = None,
              max_iter: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """x >= 0 minimising ``x^T G x - 2 c^T x`` and the boolean mask of its free (positive) variables.

    ``free_start``: the free set to start from (a previous solution's); None starts from all zero. ``max_iter``
    bounds the outer iterations (default 3 n); on reaching it the last feasible iterate is returned.
    """
    n = len(rhs)
    max_iter = 3 * n if max_iter is None else max_iter
    tol = GRADIENT_TOL * max(float(np.abs(rhs).max()), 1.0)
    free = np.zeros(n, dtype=bool) if free_start is None else free_start.copy()
    # Warm start: the free set's minimiser, with variables it drives negative made zero until it is feasible.
    x = _solve_free(gram, rhs, free)
    while (x[free] <= 0.0).any():
        free &= x > 0.0
        x = _solve_free(gram, rhs, free)
    for _ in range(max_iter):
        grad = rhs - gram @ x  # minus half the gradient: positive where increasing x_j lowers the objective
        candidates = np.where(free, -np.inf, grad)
        j = int(candidates.argmax())
        if candidates[j] <= tol:
            break
        free[j] = True
        z = _solve_free(gram, rhs, free)
        if z[j] <= 0.0:  # the entering variable cannot grow (its gradient was at rounding level): optimal
            free[j] = False
            break
        # Inner loop: step from x towards z only as far as feasibility allows; free variables reaching zero leave.
        while (z[free] <= 0.0).any():
            neg = np.flatnonzero(free & (z <= 0.0))
            ratios = x[neg] / (x[neg] - z[neg])
            k = int(np.argmin(ratios))
            x = x + ratios[k] * (z - x)
            free[neg[k]] = False
            free &= x > 0.0
            x[~free] = 0.0
            z = _solve_free(gram, rhs, free)
        x = z
    return x, free

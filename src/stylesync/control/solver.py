"""The QP solver of the whole-body controller: ProxQP (proxsuite, dense), warm-started.

One ProxQP object is kept per problem size (no, one or two supporting soles), so that each is warm-started from
its own last solution when the contact set changes back and forth during a walk.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from proxsuite import proxqp

from stylesync.control.formulation import QpProblem


@dataclass
class QpResult:
    x: np.ndarray  # (n,) the solution
    iterations: int
    solved: bool
    solve_ms: float


class ProxQpSolver:
    def __init__(self, eps_abs: float = 1e-6, max_iter: int = 200):
        self.eps_abs = eps_abs
        self.max_iter = max_iter
        self._qps: dict[tuple[int, int, int], proxqp.dense.QP] = {}
        self.iterations: list[int] = []

    def solve(self, p: QpProblem) -> QpResult:
        t0 = time.perf_counter()
        dims = (p.H.shape[0], p.A.shape[0], p.C.shape[0])
        qp = self._qps.get(dims)
        if qp is None:
            qp = proxqp.dense.QP(*dims, True)
            qp.settings.eps_abs = self.eps_abs
            qp.settings.eps_rel = 0.0
            qp.settings.max_iter = self.max_iter
            qp.settings.initial_guess = proxqp.InitialGuess.EQUALITY_CONSTRAINED_INITIAL_GUESS
            qp.init(p.H, p.g, p.A, p.b, p.C, p.l, p.u, p.l_box, p.u_box)
            self._qps[dims] = qp
        else:
            qp.settings.initial_guess = proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
            qp.update(p.H, p.g, p.A, p.b, p.C, p.l, p.u, p.l_box, p.u_box)
        qp.solve()
        res = qp.results
        solved = res.info.status == proxqp.QPSolverOutput.PROXQP_SOLVED
        self.iterations.append(int(res.info.iter))
        return QpResult(res.x.copy(), int(res.info.iter), bool(solved), (time.perf_counter() - t0) * 1e3)

    def reset(self) -> None:
        self._qps.clear()

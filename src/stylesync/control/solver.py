"""The QP solver of the whole-body controller: DAQP (a dual active-set method for dense QPs), warm-started.

Measured on the walk's QPs (66 variables, 18 equalities, 66 inequalities; docs/decisions.md): DAQP 0.07 ms a
solve, warm-started from the last tick's multipliers (3 iterations against 12 cold); ProxQP (proxsuite, dense)
0.13-0.24 ms, and its solutions of the same problems differed in the 12th digit from one run to the next, which
the simulation amplifies into different motion; an active-set method in plain C gives the same answer each time.
The warm start is kept per problem size (no, one or two supporting soles), so that each is warm-started from
its own last solution when the contact set changes back and forth during a walk.
"""

from __future__ import annotations

from ctypes import c_int
from dataclasses import dataclass

import daqp
import numpy as np

from stylesync.control.formulation import QpProblem

EQUALITY = 5  # DAQP's sense flag of an equality row
DAQP_OPTIMAL = (1, 2)  # exit flags: optimal, soft optimal


@dataclass
class QpResult:
    x: np.ndarray  # (n,) the solution
    iterations: int
    solved: bool
    exitflag: int  # DAQP's exit flag (1, 2: optimal)


class DaqpSolver:
    def __init__(self, iter_limit: int = 1000):
        self.iter_limit = iter_limit
        self._duals: dict[tuple[int, int], np.ndarray] = {}  # the last multipliers per problem size
        self._sense: dict[tuple[tuple[int, int], int], np.ndarray] = {}  # DAQP's row kinds per size and n_eq

    def solve(self, p: QpProblem) -> QpResult:
        key = p.rows.shape
        sense = self._sense.get((key, p.n_eq))
        if sense is None:
            sense = self._sense[(key, p.n_eq)] = np.zeros(len(p.rows), dtype=c_int)
            sense[:p.n_eq] = EQUALITY
        warm = self._duals.get(key)
        kwargs = {"dual_start": warm} if warm is not None else {}
        x, _, exitflag, info = daqp.solve(p.H, p.g, p.rows, p.upper, p.lower, sense, iter_limit=self.iter_limit,
                                          **kwargs)
        solved = exitflag in DAQP_OPTIMAL
        if solved:
            self._duals[key] = np.asarray(info["lam"], dtype=float)
        else:
            self._duals.pop(key, None)
        return QpResult(np.asarray(x, dtype=float), int(info["iterations"]), solved, int(exitflag))

    def reset(self) -> None:
        self._duals.clear()

"""Where the whole-body QP's solve time goes (prints figures; not a test).

    python benchmarks/bench_qp.py [--clip walk] [--duration 4] [--every 3] [--repeat 3]

Runs the built-in clip (seed 0) with the whole-body controller and keeps a copy of every ``--every``-th QP it
solves (control/formulation.py). The kept QPs are then solved again in sequence, each warm-started from the last
multipliers of its size as the controller does (control/solver.py), in three ways:

    as built      DAQP on the problem as the controller builds it: time per solve, DAQP's own setup and solve
                  times (its ``info``), iterations
    fewer rows    the same without the joint-torque rows and the hinges' limit rows; how many of its solutions
                  violate those rows (they would have to be solved again)
    pre-factored  H = L Lᵀ factored in NumPy and the variables changed to y = Lᵀ x, so that DAQP sees H = I (its
                  setup then has no factorisation to do); the factorisation and the triangular solves included

Each way is timed ``--repeat`` times, alternately; medians are printed with the largest difference of a solution
from the one as built.
"""

from __future__ import annotations

import argparse
import copy
import logging
import time
from ctypes import c_int

import daqp
import numpy as np
import scipy.linalg as sla

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.control.contacts import FORCES_PER_SOLE
from stylesync.control.formulation import QpProblem
from stylesync.control.solver import EQUALITY
from stylesync.model.character import N_DOFS, ROOT_DOFS
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator

N_TAU = N_DOFS - ROOT_DOFS  # joint-torque rows, after the equalities


def captured_problems(clip: str, duration_s: float, every: int) -> list[QpProblem]:
    """Every ``every``-th QP the whole-body controller solves on ``clip`` (seed 0), copied."""
    cfg = SessionConfig(duration_s=duration_s, seed=0, operator=OperatorConfig(clip=clip))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    solver = session.controller.solver  # type: ignore[attr-defined]
    solve, kept, count = solver.solve, [], [0]

    def keeping(problem: QpProblem):
        if count[0] % every == 0:
            kept.append(copy.deepcopy(problem))
        count[0] += 1
        return solve(problem)

    solver.solve = keeping
    session.run()
    return kept


def _daqp(h, g, rows, lower, upper, n_eq, warm):
    sense = np.zeros(len(rows), dtype=c_int)
    sense[:n_eq] = EQUALITY
    kwargs = {"dual_start": warm} if warm is not None else {}
    x, _, exitflag, info = daqp.solve(h, g, rows, upper, lower, sense, **kwargs)
    return np.asarray(x), info


def as_built(p: QpProblem, warm):
    x, info = _daqp(p.H, p.g, p.rows, p.lower, p.upper, p.n_eq, warm)
    return x, info, False


def fewer_rows(p: QpProblem, warm):
    contacts = p.n_forces // FORCES_PER_SOLE
    keep = np.r_[0:p.n_eq, p.n_eq + N_TAU:p.n_eq + N_TAU + contacts + p.n_forces]
    x, info = _daqp(p.H, p.g, np.ascontiguousarray(p.rows[keep]), p.lower[keep], p.upper[keep], p.n_eq, warm)
    r = p.rows @ x
    return x, info, bool(np.max(np.maximum(p.lower - r, r - p.upper)) > 1e-7)


def pre_factored(p: QpProblem, warm):
    chol = np.linalg.cholesky(p.H)
    rows = sla.solve_triangular(chol, p.rows.T, lower=True).T  # A L^-T
    g = sla.solve_triangular(chol, p.g, lower=True)
    y, info = _daqp(np.eye(len(g)), g, np.ascontiguousarray(rows), p.lower, p.upper, p.n_eq, warm)
    return sla.solve_triangular(chol.T, y, lower=False), info, False


def timed(way, problems: list[QpProblem]) -> dict:
    warm: dict = {}
    xs, setup, solve, iters, violated = [], 0.0, 0.0, 0, 0
    t0 = time.perf_counter()
    for p in problems:
        key = (p.rows.shape, p.n_eq)
        x, info, bad = way(p, warm.get(key))
        warm[key] = np.asarray(info["lam"])
        xs.append(x)
        setup += info["setup_time"]
        solve += info["solve_time"]
        iters += int(info["iterations"])
        violated += bad
    n = len(problems)
    return {"us": (time.perf_counter() - t0) / n * 1e6, "setup_us": setup / n * 1e6, "solve_us": solve / n * 1e6,
            "iterations": iters / n, "violated": violated, "x": xs}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="walk")
    ap.add_argument("--duration", type=float, default=4.0, help="simulated seconds of the run the QPs come from")
    ap.add_argument("--every", type=int, default=3, help="keep every this many QPs")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    logging.getLogger("stylesync").setLevel(logging.ERROR)
    problems = captured_problems(args.clip, args.duration, args.every)
    sizes = sorted({p.rows.shape for p in problems})
    print(f"{len(problems)} QPs of the {args.clip} (seed 0, {args.duration:g} s), sizes (rows, variables): "
          + ", ".join(f"{r}x{c}" for r, c in sizes))
    ways = {"as built": as_built, "fewer rows": fewer_rows, "pre-factored": pre_factored}
    runs: dict[str, list[dict]] = {name: [] for name in ways}
    for _ in range(max(args.repeat, 1)):
        for name, way in ways.items():
            runs[name].append(timed(way, problems))
    reference = runs["as built"][0]["x"]
    print(f"{'':14s} {'per solve':>10s} {'DAQP setup':>11s} {'DAQP solve':>11s} {'iterations':>10s} "
          f"{'violated':>8s} {'max |x - x as built|':>21s}")
    for name, rs in runs.items():
        med = {k: float(np.median([r[k] for r in rs])) for k in ("us", "setup_us", "solve_us", "iterations")}
        diff = max(float(np.max(np.abs(a - b))) for a, b in zip(rs[0]["x"], reference, strict=True))
        print(f"{name:14s} {med['us']:8.1f} µs {med['setup_us']:8.1f} µs {med['solve_us']:8.1f} µs "
              f"{med['iterations']:10.1f} {rs[0]['violated']:8d} {diff:21.2e}")


if __name__ == "__main__":
    main()

"""Where a control tick's time goes in the running pipeline (prints figures; not a test).

    python benchmarks/tick_breakdown.py [--clip walk] [--duration 12] [--seed 0] [--motion-ahead]

Runs the built-in clip headless as `stylesync demo` does (the operator side prefetched; with ``--motion-ahead`` as
`stylesync demo --motion-ahead` does, the motion stage in its worker, whose calls are then not timed: motion_ahead.py)
with a timer around each of the calls listed in PARTS, and prints each call's mean time per control tick [µs] and per
call, beside the session's own stages. The same calls timed in a loop by themselves cost two to three times less: in the
pipeline each runs after the engine and the other stages have evicted its data from the caches (docs/decisions.md, "The
control tick on the model and the QP: where the time goes"). The timers add about 0.2 µs a call.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import logging
import time
from collections.abc import Callable

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator

# (module, attribute path, label): the calls timed, as "stage: part"
PARTS = [
    ("stylesync.prefetch", "OperatorPrefetch.tick", "processing: the operator side's row unpacked"),
    ("stylesync.sim.pybullet_backend", "PyBulletBackend.read_state", "motion: the character's state read"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._track_stance", "motion: stance tracking"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._retarget_lower_body", "motion: lower-body retargeting"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._plan_feet", "motion: feet planned"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._solve_legs", "motion: leg IK"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._map_upper_body", "motion: upper body"),
    ("stylesync.motion.pose_optimization", "MotionOptimizer._reference", "motion: the reference pose"),
    ("stylesync.model.character_model", "CharacterModel.update", "control: the model's update (Pinocchio)"),
    ("stylesync.control.controller", "ControllerBase._error_and_reference_velocity",
     "control: joint error, reference rate"),
    ("stylesync.control.contacts", "SoleContact.update", "control: the soles"),
    ("stylesync.control.formulation", "WholeBodyFormulation.build", "control: the QP's assembly"),
    ("stylesync.control.solver", "DaqpSolver.solve", "control: the QP's solve (DAQP)"),
    ("stylesync.session", "Session._log", "session: the tick's log"),
    ("stylesync.session", "Session._detect_fall", "session: fall detection"),
]


def _timed(f: Callable, totals: dict[str, list[float]], label: str) -> Callable:
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return f(*args, **kwargs)
        finally:
            entry = totals[label]
            entry[0] += time.perf_counter() - t0
            entry[1] += 1

    return wrapper


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="walk")
    ap.add_argument("--duration", type=float, default=12.0, help="simulated seconds")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--motion-ahead", action="store_true", help="the motion stage a tick ahead in its worker")
    args = ap.parse_args()
    logging.getLogger("stylesync").setLevel(logging.ERROR)
    totals: dict[str, list[float]] = {label: [0.0, 0] for *_, label in PARTS}
    for module, path, label in PARTS:
        owner = importlib.import_module(module)
        *outer, name = path.split(".")
        for part in outer:
            owner = getattr(owner, part)
        setattr(owner, name, _timed(getattr(owner, name), totals, label))
    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, operator=OperatorConfig(clip=args.clip),
                        motion_ahead=args.motion_ahead)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    result = Session(cfg, source).run()
    ticks = len(result.stage_ms["motion"])
    steps = len(result.stage_ms["physics"])
    wall_ms = result.wall_duration_s * 1e3
    print(f"clip {args.clip}, simulated {result.sim_duration_s:.2f} s{' (fell)' if result.fell else ''}, "
          f"{ticks} control ticks, {result.sim_duration_s / result.wall_duration_s:.2f}x real time, "
          f"operator side {'prefetched' if result.operator_prefetched else 'in this process'}, "
          f"motion stage {'ahead in its worker' if args.motion_ahead else 'in this process'}")
    print(f"wall time per control tick: {wall_ms / ticks:.3f} ms")
    print("the session's stages, mean per control tick [ms]:")
    for name, values in result.stage_ms.items():
        if len(values):
            print(f"  {name:16s} {np.sum(values) / ticks:7.3f}"
                  f"{f'   ({steps / ticks:.1f} physics steps)' if name in ('torques', 'physics') else ''}")
    print("timed calls, mean per control tick [µs] (per call, calls per tick):")
    for *_, label in PARTS:
        total_s, calls = totals[label]
        if calls:
            print(f"  {label:48s} {total_s / ticks * 1e6:7.1f}   ({total_s / calls * 1e6:6.1f}, {calls / ticks:.1f})")


if __name__ == "__main__":
    main()

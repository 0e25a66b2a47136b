"""How the development suite's falls end (prints figures; a tool, not a test).

    python benchmarks/fall_endings.py DEV_SUITE_JSON [--version "this version"] [--window 0.6]

Reads the runs of one version from a development-suite JSON (``benchmarks/dev_suite.py --out DIR`` writes
``DIR/dev_suite.json``), runs each distinct fall again in this checkout to its fall time (the suite's configuration:
the Kinect sensor model with the seed, a recorded file started in its first pose), and prints per fall:

    own       the share of the last ``--window`` seconds spent in steps the character takes on its own
    steps     the number of such steps in the run
    waits     per step, the time from its landing falling due (its target below the ground, whole_body.py) to its
              foot touching [s], the last few; ``open`` is a wait still running at the fall
    pelvis    the pelvis height's change over the last second [m]

This version's falls are the ones traced; a JSON written by another version gives the runs, not the answers, when
the code has changed since.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
from concurrent.futures import ProcessPoolExecutor

from stylesync.control.whole_body import recovery_landing_due
from stylesync.metrics.dev_suite import suite_config
from stylesync.session import Session
from stylesync.sources.registry import open_source


def trace_fall(job: tuple[str, str, int, float, float]) -> dict:
    """One fall run again to its time: the share of its last ``window_s`` in recovery steps, the steps' due waits."""
    spec, clip, seed, fall_s, window_s = job
    logging.disable(logging.WARNING)
    opened = open_source(spec, seed=seed, duration_s=12.0)
    cfg, _ = suite_config(spec, opened, seed, 12.0)
    session = Session(dataclasses.replace(cfg, duration_s=min(cfg.duration_s, fall_s + 0.05)), opened.source)
    own_ticks, ticks, steps, waits = [0], [0], [0], []
    due_since: list[float] = []
    in_step = [False]
    pelvis_z: list[tuple[float, float]] = []

    def on_tick(state, ref) -> None:
        targets = ref.recovery_ankle_world or {}
        if targets and not in_step[0]:
            steps[0] += 1
        in_step[0] = bool(targets)
        due = any(recovery_landing_due(t) for t in targets.values())
        if due and not due_since:
            due_since.append(state.time_s)
        elif not due and due_since:
            waits.append(state.time_s - due_since.pop())
        if state.time_s >= fall_s - window_s:
            ticks[0] += 1
            own_ticks[0] += bool(targets)
        if state.time_s >= fall_s - 1.0:
            pelvis_z.append((state.time_s, float(state.root_pos_world[2])))

    session.on_tick = on_tick
    try:
        session.run()
    finally:
        opened.source.close()
    return {"clip": clip, "seed": seed, "fall_s": fall_s, "own": own_ticks[0] / max(ticks[0], 1), "steps": steps[0],
            "waits": waits[-4:], "open": fall_s - due_since[0] if due_since else None,
            "pelvis_m": pelvis_z[-1][1] - pelvis_z[0][1] if pelvis_z else 0.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", help="a development suite's dev_suite.json")
    ap.add_argument("--version", default="this version", help="the version whose falls are traced")
    ap.add_argument("--window", type=float, default=0.6, help="the time before each fall looked at [s]")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    seen: set[tuple[str, int]] = set()
    jobs = []
    for r in json.loads(open(args.runs).read()):
        key = (r["spec"], r["seed"])
        if r["version"] == args.version and r.get("fell") and r["category"] != "acrobatics" and key not in seen:
            seen.add(key)
            jobs.append((r["spec"], r["clip"], r["seed"], r["fall_time_s"], args.window))
    print(f"{len(jobs)} distinct falls of '{args.version}' (every category but acrobatics), traced in this checkout")
    print(f"{'clip':>16} {'seed':>4} {'fall [s]':>8} {'own':>5} {'steps':>5} {'pelvis [m]':>10}  due waits [s]")
    mostly_own = 0
    with ProcessPoolExecutor(args.workers) as pool:
        for f in pool.map(trace_fall, jobs):
            mostly_own += f["own"] >= 0.5
            waits = " ".join(f"{w:.2f}" for w in f["waits"]) + (f" open {f['open']:.2f}" if f["open"] is not None
                                                                 else "")
            print(f"{f['clip']:>16} {f['seed']:4d} {f['fall_s']:8.2f} {f['own']:5.2f} {f['steps']:5d} "
                  f"{f['pelvis_m']:+10.2f}  {waits}")
    print(f"{mostly_own} of {len(jobs)} falls spent at least half of their last {args.window:.1f} s in recovery steps")


if __name__ == "__main__":
    main()

"""The long fuzz pass: every target of targets.py, many mutated inputs each, one process per target.

    python fuzz/run.py --inputs 100000 --workers 2

Prints per target: inputs tried, accepted, clean errors (a one-line StylesyncError, a rejected packet, exit 2),
tracebacks (any other exception: the first of each kind with its input saved under --out), hangs (an input that
takes more than --timeout seconds) and the process's peak resident memory.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import multiprocessing as mp
import random
import resource
import signal
import sys
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


class _Hang(Exception):
    pass


def _alarm(signum, frame):
    raise _Hang


def fuzz_target(name: str, inputs: int, seed: int, timeout_s: float, out: str) -> dict:
    from targets import all_targets, mutate

    logging.disable(logging.CRITICAL)
    target = next(t for t in all_targets() if t.name == name)
    rng = random.Random(seed)
    counts = {"target": name, "inputs": 0, "accepted": 0, "clean_errors": 0, "tracebacks": 0, "hangs": 0}
    kinds: dict[str, int] = {}
    signal.signal(signal.SIGALRM, _alarm)
    t0 = time.perf_counter()
    base = target.seed
    for k in range(inputs):
        data = mutate(base, rng)
        counts["inputs"] += 1
        signal.setitimer(signal.ITIMER_REAL, timeout_s)
        try:
            with contextlib.redirect_stderr(io.StringIO()):
                refused = target(data)
            counts["clean_errors" if refused else "accepted"] += 1
        except _Hang:
            counts["hangs"] += 1
            Path(out, f"{name}-hang-{k}.bin").write_bytes(data)
        except Exception as exc:  # noqa: BLE001 - what the pass looks for
            counts["tracebacks"] += 1
            last = traceback.extract_tb(exc.__traceback__)[-1]
            kind = f"{type(exc).__name__} at {Path(last.filename).name}:{last.lineno}"
            if kind not in kinds:
                Path(out, f"{name}-traceback-{len(kinds)}.bin").write_bytes(data)
            kinds[kind] = kinds.get(kind, 0) + 1
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
    if hasattr(target, "close"):
        target.close()
    counts["seconds"] = round(time.perf_counter() - t0, 1)
    counts["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    counts["traceback_kinds"] = kinds
    return counts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inputs", type=int, default=100_000, help="inputs per target")
    ap.add_argument("--targets", default="", help="comma-separated target names (default: all)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds after which an input counts as a hang")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/fuzz", help="where inputs that fail are saved")
    args = ap.parse_args()
    from targets import all_targets

    names = [t.name for t in all_targets()]
    if args.targets:
        names = [n for n in names if n in args.targets.split(",")]
    Path(args.out).mkdir(parents=True, exist_ok=True)
    ctx = mp.get_context("spawn")
    with ctx.Pool(args.workers, maxtasksperchild=1) as pool:
        jobs = [pool.apply_async(fuzz_target, (n, args.inputs, args.seed, args.timeout, args.out)) for n in names]
        print(f"{'target':10s} {'inputs':>8s} {'accepted':>9s} {'clean err':>9s} {'tracebacks':>10s} {'hangs':>6s} "
              f"{'seconds':>8s} {'peak MB':>8s}")
        for job in jobs:
            r = job.get()
            print(f"{r['target']:10s} {r['inputs']:8d} {r['accepted']:9d} {r['clean_errors']:9d} "
                  f"{r['tracebacks']:10d} {r['hangs']:6d} {r['seconds']:8.1f} {r['peak_rss_mb']:8.1f}", flush=True)
            for kind, n in r["traceback_kinds"].items():
                print(f"    {n} x {kind}")


if __name__ == "__main__":
    main()

"""How the development suite's UHC terminations come about (prints figures; a tool, not a test).

    python benchmarks/uhc_endings.py DEV_SUITE_JSON [--version "this version"] [--categories "walk,styled walk"]
                                     [--workers 2]

The field's termination criterion (UHC, PHC) ends an imitation run once the mean distance of the character's joints
from the operator's (scaled onto the character from where both started, ``metrics.imitation``) exceeds 0.5 m. This
tool reads the runs of one version from a development-suite JSON (``benchmarks/dev_suite.py --out DIR`` writes
``DIR/dev_suite.json``), runs each distinct run that ended by it without a fall again in this checkout to its
termination (the suite's configuration: the Kinect sensor model with the seed, a recorded file started in its first
pose), and splits the distance at the termination into where the character's pelvis is from his and how its pose
differs from his:

    along     the pelvis's offset from his along his way over the ground (his pelvis's displacement over the last
              0.5 s; < 0: behind him) [m]
    across    its distance to the side of his way [m]
    height    its height less his [m]
    pose      the mean distance of the joints from his with both pelvises put together (root-relative) [m]
    his, its  his speed over the ground and the character's over the last second (scaled; straight-line) [m/s]
    cause     the largest of the four: ``behind`` or ``ahead`` along his way, ``aside``, ``height``, ``pose``;
              ``in place`` where he went less than 0.1 m in the last 0.5 s and the pelvis's offset is the largest

The four parts do not add up to the distance (it is a mean of lengths); the largest says what the termination
mostly is. This version's runs are the ones traced; a JSON written by another version gives the runs, not the
answers, when the code has changed since.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor

from stylesync.metrics import imitation as im
from stylesync.metrics.dev_suite import suite_config
from stylesync.session import Session
from stylesync.sources.registry import open_source


def trace_termination(job: tuple[str, str, str, int, float]) -> dict:
    """One run ended by the UHC termination, run again to just past it: metrics.imitation.termination_split at
    its tick."""
    spec, clip, category, seed, end_s = job
    logging.disable(logging.WARNING)
    opened = open_source(spec, seed=seed, duration_s=12.0)
    cfg, _ = suite_config(spec, opened, seed, 12.0)
    try:
        result = Session(dataclasses.replace(cfg, duration_s=min(cfg.duration_s, end_s + 0.05)), opened.source).run()
    finally:
        opened.source.close()
    lg = result.log
    t, ch = lg.array("t"), lg.array("ch_joints")
    ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
    k = im.uhc_fall_index(ch, ref)
    row = {"clip": clip, "category": category, "seed": seed, "suite_s": end_s}
    if k is None:  # the code has changed since the JSON was written
        return row | {"termination_s": None}
    return row | {"termination_s": float(t[k])} | im.termination_split(t, ch, ref, k)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", help="a development suite's dev_suite.json")
    ap.add_argument("--version", default="this version", help="the version whose terminations are traced")
    ap.add_argument("--categories", default="walk,styled walk,uneven", help="comma-separated suite categories")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    categories = [c.strip() for c in args.categories.split(",") if c.strip()]
    seen: set[tuple[str, int]] = set()
    jobs = []
    for r in json.loads(open(args.runs).read()):
        key = (r["spec"], r["seed"])
        if (r["version"] == args.version and r["category"] in categories and not r.get("fell")
                and r.get("uhc_fall_time_s") is not None and key not in seen):
            seen.add(key)
            jobs.append((r["spec"], r["clip"], r["category"], r["seed"], r["uhc_fall_time_s"]))
    print(f"{len(jobs)} distinct runs of '{args.version}' ended by the UHC termination without a fall "
          f"({', '.join(categories)}), traced in this checkout")
    print(f"{'clip':>32} {'seed':>4} {'at [s]':>6} {'along':>6} {'across':>6} {'height':>6} {'pose':>5} "
          f"{'his':>5} {'its':>5}  cause")
    tally: dict[str, Counter] = defaultdict(Counter)
    with ProcessPoolExecutor(args.workers) as pool:
        for f in pool.map(trace_termination, jobs):
            if f["termination_s"] is None:
                print(f"{f['clip']:>32} {f['seed']:4d} no termination in this checkout (the suite's at "
                      f"{f['suite_s']:.2f} s)")
                continue
            tally[f["category"]][f["cause"]] += 1
            print(f"{f['clip']:>32} {f['seed']:4d} {f['termination_s']:6.2f} {f['along']:+6.2f} {f['across']:6.2f} "
                  f"{f['height']:+6.2f} {f['pose']:5.2f} {f['his_mps']:5.2f} {f['its_mps']:5.2f}  {f['cause']}")
    for category, counts in tally.items():
        print(f"{category}: " + ", ".join(f"{cause} {n}" for cause, n in counts.most_common()))


if __name__ == "__main__":
    main()

"""This version's controller against an earlier version's (a git ref), measured in one run on the same machine.

    python benchmarks/compare_controllers.py --baseline 9e63c3d --seeds 48

Both versions (HEAD and the baseline) are checked out in temporary git worktrees and run in their own interpreters
(versions.py), so both use their own code with this environment's libraries. Measured for each, alternately: the
demo walk (seed 0: fall, steps, transition delays), the walk over sensor-noise seeds 0..N-1 for 12 s (runs that
complete), standing 60 s (COM drift after settling), the control update's cost (median over the walk's ticks) and
the realtime factor against physics alone (the engine alone measured in this process). Figures are printed as a
Markdown table.
"""

from __future__ import annotations

import argparse
import sys

from versions import checkouts, probe

from stylesync.config import SessionConfig
from stylesync.metrics.bench import physics_only_rtf

# Run inside each version's interpreter: only APIs both versions share.
_PROBE = r'''
import json, logging, sys, time
import numpy as np
logging.getLogger("stylesync").setLevel(logging.ERROR)
from stylesync.config import OperatorConfig, SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator
from stylesync.metrics.summary import summarize
what, arg = sys.argv[1], sys.argv[2]
def run(clip, seed, duration):
    cfg = SessionConfig(duration_s=duration, seed=seed, operator=OperatorConfig(clip=clip))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, duration + 1.0, seed)
    session = Session(cfg, source)
    return session.run()
out = {}
if what == "walk":
    r = run("walk", int(arg), 12.0)
    m = summarize(r)
    out = {"fell": r.fell, "fall_time_s": r.fall_time_s, "operator_steps": m["operator_steps"],
           "character_steps": m["character_steps"], "delay_max_s": m["state_transition_delay_s"]["max"],
           "control_update_ms_p50": float(np.median(r.stage_ms["control_update"])),
           "realtime_factor": r.sim_duration_s / r.wall_duration_s}
elif what == "stand":
    r = run("stand", 0, float(arg))
    t = r.log.array("t")
    com = np.stack([r.log.array("com_x"), r.log.array("com_y")], axis=1)
    settled = com[t >= 2.0]
    out = {"fell": r.fell, "drift_m": float(np.linalg.norm(settled - settled[0], axis=1).max()),
           "control_update_ms_p50": float(np.median(r.stage_ms["control_update"])),
           "realtime_factor": r.sim_duration_s / r.wall_duration_s}
print(json.dumps(out))
'''


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="9e63c3d", help="git ref of the earlier version")
    ap.add_argument("--seeds", type=int, default=48)
    ap.add_argument("--stand", type=float, default=60.0, help="simulated seconds of the standing run")
    args = ap.parse_args()
    with checkouts({"this version": "HEAD", f"baseline {args.baseline}": args.baseline}) as trees:
        rows: dict[str, dict] = {name: {"walks": [], "phys": []} for name in trees}
        for seed in range(args.seeds):  # alternated, so that both see the machine's slow and fast spells
            for name, path in trees.items():
                rows[name]["walks"].append(probe(path, _PROBE, "walk", str(seed)))
            print(f"seed {seed} done", file=sys.stderr, flush=True)
        for name, path in trees.items():
            rows[name]["stand"] = probe(path, _PROBE, "stand", str(args.stand))
            rows[name]["phys"].append(physics_only_rtf(SessionConfig(duration_s=12.0), 12.0))
    print("| controller | walk seed 0 | steps (char/op) | max delay [s] | seeds completing 12 s | standing 60 s drift "
          "[cm] | control update p50 [ms] | realtime factor (walk) / physics alone |")
    print("|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        w0 = r["walks"][0]
        done = sum(not w["fell"] for w in r["walks"])
        upd = float(sorted(w["control_update_ms_p50"] for w in r["walks"])[len(r["walks"]) // 2])
        rtf = float(sorted(w["realtime_factor"] for w in r["walks"])[len(r["walks"]) // 2])
        phys = r["phys"][0]
        fell = f"fell at {w0['fall_time_s']:.2f} s" if w0["fell"] else "no fall"
        falls = ", ".join(f"{s}: {w['fall_time_s']:.1f} s" for s, w in enumerate(r["walks"]) if w["fell"])
        print(f"| {name} | {fell} | {w0['character_steps']}/{w0['operator_steps']} | {w0['delay_max_s']:.3f} | "
              f"{done} of {len(r['walks'])}{f' (falls {falls})' if falls else ''} | "
              f"{100 * r['stand']['drift_m']:.2f}{' (fell)' if r['stand']['fell'] else ''} | {upd:.3f} | "
              f"{rtf:.2f}x / {phys:.2f}x = {rtf / phys:.2f} |")


if __name__ == "__main__":
    main()

"""The development suite: every shared clip, several sensor seeds, two versions of stylesync in the same run.

    python benchmarks/dev_suite.py --baseline 9e63c3d --seeds 3 --duration 12 --out out/dev_suite

Clips: the humanoid3d clips of pybullet_data and every clip of ../shared/mocap (cmu, cmu-dev, deepmimic), each
with a category (walk, styled walk, uneven, run, jump, kick, arms, acrobatics). Both versions (this checkout's
HEAD and --baseline) are checked out in temporary git worktrees and each run goes through its own interpreter,
alternating versions, two at a time (one per core). A run lasts the clip (at most --duration seconds, the 1 s
standing lead-in of a clip, or the rest after a recorded file, included) through the Kinect sensor model with the
given seed. Per category: runs, clips that could be opened, completion (no fall), runs through the clip (no fall
before the clip's end; a fall in the rest after it counts against completion only), runs without a UHC/PHC
termination, mean fall time, MPJPE (global, root-relative), steps (character / operator), the median of how far
the character went along its operator's path (metrics/imitation.path_progress) and the median of the runs' largest
transition delays; then, per category, the runs each version completes and the other does not, with the p-value
of the difference (stylesync.metrics.paired_outcomes). Nothing is tuned per clip: the same settings for every run.
Writes dev_suite.md and dev_suite.json under --out.
"""

from __future__ import annotations

import argparse
import inspect
import json
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from versions import REPO, checkouts, probe

from stylesync.metrics import imitation
from stylesync.metrics.dev_suite import ORDER, table
from stylesync.metrics.dev_suite import clip_specs as suite_clips
from stylesync.metrics.paired_outcomes import paired_table

SHARED = REPO.parent / "shared" / "mocap"
# Run inside each checked-out version, old ones included, which have no stylesync.metrics.dev_suite to call: the
# same steps as its run_clip, written against the API every version has.
_PROBE = r'''
import dataclasses, json, logging, sys
logging.disable(logging.CRITICAL)
from stylesync.config import OperatorConfig, SessionConfig
from stylesync.errors import StylesyncError
from stylesync.metrics.summary import summarize
from stylesync.session import Session
from stylesync.sources.registry import open_source
# <termination_split>
spec, seed, duration = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
try:
    opened = open_source(spec, seed=seed, duration_s=duration)
except StylesyncError as exc:
    print(json.dumps({"error": str(exc)[:200]}))
    raise SystemExit(0)
length = min(duration, float(opened.duration_s or duration))
op = OperatorConfig()
in_motion = spec.startswith(("bvh:", "k4a-json:")) and getattr(op, "start_in_motion", False)
clip_end = length - (min(getattr(op, "rest_after_clip_s", 0.0), length) if in_motion else 0.0)
cfg = SessionConfig(duration_s=length, seed=seed, operator=OperatorConfig(),
                    clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
try:
    result = Session(cfg, opened.source).run()
finally:
    opened.source.close()
m = summarize(result)
if "path_progress" not in m:  # a version before metrics/imitation.path_progress: the same definition, here
    import numpy as np
    lg = result.log
    ch, op, scale = lg.array("ch_joints")[:, 0], lg.array("op_joints")[:, 0], lg.array("scale")
    dc, dr = ch[-1, :2] - ch[0, :2], scale[-1] * (op[-1, :2] - op[0, :2])
    length = float(np.hypot(dr[0], dr[1]))
    m["path_progress"] = float(dc @ dr) / length**2 if length >= 0.5 else None
if "step_width_m" not in m:  # a version before metrics/imitation.step_widths_m: the same definition, here
    import numpy as np
    lg = result.log
    ch = lg.array("ch_joints")
    op = ch[0, 0, :2] + lg.array("scale")[:, None, None] * (lg.array("op_joints")[..., :2]
                                                            - lg.array("op_joints")[0, 0, :2])
    def width(pos, states):  # left ankle (5) left of the right (8) along the hip line (right hip 6 to left 3)
        s = np.asarray(states)
        ticks = np.where((s[1:] == 1) & (s[:-1] != 1))[0] + 1
        if not len(ticks):
            return None
        hips = pos[ticks, 3, :2] - pos[ticks, 6, :2]
        across = hips / np.maximum(np.linalg.norm(hips, axis=1, keepdims=True), 1e-9)
        return round(float(np.median(np.einsum("ij,ij->i", pos[ticks, 5, :2] - pos[ticks, 8, :2], across))), 4)
    m["step_width_m"] = {"character": width(ch[..., :2], lg.array("char_state")),
                         "operator": width(op, lg.array("op_state"))}
if "mpjpe_global_before_uhc_mm" not in m and len(result.log.array("t")) >= 3:
    # a version before metrics/imitation.mpjpe_before_termination_mm: the same definition on that version's own
    # scaling, termination and MPJPE (metrics/imitation.py has had all three since its first version)
    from stylesync.metrics import imitation as im
    lg = result.log
    ch = lg.array("ch_joints")
    ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
    uhc = im.uhc_fall_index(ch, ref)
    end = len(ch) if uhc is None else max(uhc, 1)
    m["mpjpe_global_before_uhc_mm"] = round(im.mpjpe_mm(ch[:end], ref[:end]), 1)
    m["mpjpe_root_before_uhc_mm"] = round(im.mpjpe_mm(ch[:end], ref[:end], root_relative=True), 1)
if "uhc_cause" not in m and m.get("uhc_fall_time_s") is not None:
    # a version before metrics/imitation.termination_split: this checkout's definition, its source put in below
    from stylesync.metrics import imitation as im
    lg = result.log
    t, ch = lg.array("t"), lg.array("ch_joints")
    ref = im.scale_operator_to_character(lg.array("op_joints"), lg.array("scale"), ch[0, 0])
    m["uhc_cause"] = termination_split(t, ch, ref, im.uhc_fall_index(ch, ref))["cause"]
keys = ("fell", "fall_time_s", "sim_duration_s", "operator_steps", "character_steps", "state_transition_delay_s",
        "mpjpe_global_mm", "mpjpe_root_mm", "mpjpe_global_before_uhc_mm", "mpjpe_root_before_uhc_mm",
        "uhc_fall_time_s", "uhc_cause", "path_progress", "realtime_factor", "fall_reason", "step_width_m")
print(json.dumps({"clip_end_s": clip_end, **{k: m.get(k) for k in keys}}))
'''
# termination_split's source (and its constants) for the versions before it: one definition, not a copy of it
_PROBE = _PROBE.replace("# <termination_split>\n", "import numpy as np\n" + "".join(
    f"{name} = {getattr(imitation, name)!r}\n" for name in ("TERMINATION_WAY_WINDOW_S", "TERMINATION_IN_PLACE_M"))
    + inspect.getsource(imitation.termination_split))


def clip_specs() -> list[tuple[str, str, str]]:
    """(spec, name, category) of every clip of the suite (stylesync.metrics.dev_suite)."""
    return suite_clips(SHARED)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="9e63c3d", help="git ref of the earlier version ('none': this one only)")
    ap.add_argument("--version", default="HEAD",
                    help="git ref of this version ('worktree': the checkout's files as they are, uncommitted "
                         "changes included)")
    ap.add_argument("--only", default="", help="comma-separated categories to run (default: all)")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--first-seed", type=int, default=0, help="seeds run: first-seed .. first-seed + seeds - 1")
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/dev_suite")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    clips = [c for c in clip_specs() if not args.only or c[2] in args.only.split(",")]
    refs = {} if args.version == "worktree" else {"this version": args.version}
    if args.baseline != "none":
        refs[f"baseline {args.baseline}"] = args.baseline
    with checkouts(refs) as checked_out:
        trees = {"this version": REPO / "src", **checked_out} if args.version == "worktree" else checked_out
        seeds = range(args.first_seed, args.first_seed + args.seeds)
        jobs = [(spec, name, cat, seed, v) for spec, name, cat in clips for seed in seeds for v in trees]

        def run(job):
            spec, name, cat, seed, v = job
            r = probe(trees[v], _PROBE, spec, str(seed), str(args.duration))
            status = r.get("error") or (f"fell {r['fall_time_s']:.2f} s" if r["fell"] else "complete")
            print(f"{v:>20} {name:>32} seed {seed}: {status}", file=sys.stderr, flush=True)
            return {"clip": name, "spec": spec, "category": cat, "seed": seed, "version": v, **r}

        with ThreadPoolExecutor(max_workers=args.workers) as pool:
            rows = list(pool.map(run, jobs))
    md = table(rows, list(trees))
    if len(trees) > 1:  # each version against the baseline: "complete, not baseline ..." are the runs it gained
        md += "\n\n" + paired_table(rows, list(trees)[::-1], ORDER)
    (out / "dev_suite.json").write_text(json.dumps(rows, indent=1))
    (out / "dev_suite.md").write_text(md + "\n")
    print(md)


if __name__ == "__main__":
    main()

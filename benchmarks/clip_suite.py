"""Run `stylesync demo` on every humanoid3d clip of pybullet_data (and the walk without LIPM), print a Markdown table.

    python benchmarks/clip_suite.py [--duration 12] [--out out/suite]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from stylesync.sources.deepmimic_clip import builtin_clip_names


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--out", default="out/suite")
    args = ap.parse_args()
    runs = [("walk", []), ("walk", ["--no-lipm"]), ("stand", [])]
    runs += [(c, []) for c in builtin_clip_names() if c not in ("walk",)]
    rows = []
    for clip, extra in runs:
        out = Path(args.out) / (clip + ("-nolipm" if extra else ""))
        cmd = [sys.executable, "-m", "stylesync.cli", "demo", "--clip", clip, "--duration", str(args.duration),
               "--out", str(out), *extra]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            rows.append(f"| {clip} {' '.join(extra)} | error: {proc.stderr.strip().splitlines()[-1:]} |")
            continue
        m = json.loads((out / "metrics.json").read_text())
        d = m["state_transition_delay_s"]
        fall = f"{m['fall_time_s']:.2f}" if m["fall_time_s"] is not None else "-"
        delay = f"{d['max']:.3f}" if d["max"] is not None else "-"
        rows.append(
            f"| {clip}{' (LIPM off)' if extra else ''} | {'yes' if m['fell'] else 'no'} | {fall} | "
            f"{m['operator_steps']} | {m['character_steps']} | {delay} | "
            f"{m['com_error_m']['mean']:.3f} | {m['joint_error_deg']['mean']:.1f} | {m['realtime_factor']:.2f} |")
        print(rows[-1], flush=True)
    print()
    print("| clip | fell | fall time [s] | operator steps | character steps | max transition delay [s]"
          " | COM error mean [m] | joint error mean [deg] | realtime factor |")
    print("|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()

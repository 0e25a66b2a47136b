"""How far the character's legs turn about their own axes in runs of the development suite (prints figures; a tool
for explaining falls).

    python benchmarks/leg_twist.py walk:0 spin:0 spinkick:9 [--duration 12]

Each argument is a development-suite clip (`stylesync bench --suite dev`: a humanoid3d clip or a file of
../shared/mocap) and a sensor seed, run as the suite runs it (benchmarks/trace_run.py). A hip's or an ankle's twist is
the turn of its local rotation about the child segment's long axis (the model's y; the swing-twist decomposition,
rotations.twist_angle), of the character's joints and of the reference's targets, over the run's control ticks up to
its fall: the 95th percentile and the largest of its magnitude [deg], left hip, right hip, left ankle, right ankle
(docs/decisions.md, "Legs that twist about their own axis").
"""

from __future__ import annotations

import numpy as np
from trace_run import run_suite_clip, runs_main

from stylesync import rotations as rot
from stylesync.model.character import JOINT_NAMES

TWISTING = ("left_hip", "right_hip", "left_ankle", "right_ankle")
SEGMENT_AXIS = np.array([0.0, 1.0, 0.0])  # a leg segment's long axis in its model frame (the model is Y-up)


def _twists_deg(joint_pos: np.ndarray, joints: list[int]) -> list[float]:
    return [float(np.degrees(rot.twist_angle(joint_pos[k], SEGMENT_AXIS))) for k in joints]


def _fmt(x: np.ndarray) -> str:
    return ", ".join(f"{v:.0f}" for v in x)


def twist_figures(clip: str, seed: int, duration_s: float) -> str:
    """One line of figures for a run of ``clip`` with sensor seed ``seed``."""
    joints = [JOINT_NAMES.index(name) for name in TWISTING]
    rows: list[list[float]] = []  # per control tick: time [s], the joints' twists, the reference's [deg]

    def on_tick(state, ref) -> None:
        rows.append([state.time_s, *_twists_deg(state.joint_pos, joints), *_twists_deg(ref.joint_pos, joints)])

    result, _, _ = run_suite_clip(clip, seed, duration_s, lambda session: on_tick)
    a = np.abs(np.array(rows))
    if result.fell and result.fall_time_s is not None:
        a = a[a[:, 0] <= result.fall_time_s]
    outcome = f"fell at {result.fall_time_s:.2f} s" if result.fell else f"completed {result.sim_duration_s:.1f} s"
    return (f"{clip} seed {seed} ({outcome}): twist p95 {_fmt(np.percentile(a[:, 1:5], 95, axis=0))}, "
            f"largest {_fmt(a[:, 1:5].max(axis=0))}; reference p95 {_fmt(np.percentile(a[:, 5:9], 95, axis=0))} [deg]")


def main() -> None:
    runs_main(__doc__, lambda clip, seed, args: twist_figures(clip, seed, args.duration), "spin:0")


if __name__ == "__main__":
    main()

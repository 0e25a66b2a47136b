"""How the character's own steps land in runs of the development suite (prints figures; a tool for explaining falls).

    python benchmarks/own_step_landings.py run:14 jog:8 jog:9 [--window 1.5] [--duration 12]

Each argument is a development-suite clip (`stylesync bench --suite dev`: a humanoid3d clip or a file of
../shared/mocap) and a sensor seed, run as the suite runs it (benchmarks/trace_run.py). Over the control ticks of the
character's own steps (motion/recovery_step.py; ``ReferencePose.recovery_ankle_world``), in the last ``--window``
seconds before a fall, or over the whole run when it completes:

    own ticks   control ticks in a step of the character's own
    max z       the swing ankle's largest height [m] (ANKLE_HEIGHT_M, 0.05 m, when the foot is on the ground)
    due, up     ticks whose landing is due (the target pressed below the ground, whole_body.recovery_landing_due)
                while the ankle is more than DUE_UP_M high: a foot that should be down and is not
    hip limit   ticks with the swing hip at its torque limit (any axis)
"""

from __future__ import annotations

import argparse

import numpy as np
from trace_run import run_suite_clip, runs_main

from stylesync.control.controller import TORQUE_LIMIT
from stylesync.control.whole_body import recovery_landing_due
from stylesync.model.character import ANKLE_HEIGHT_M, JOINT_NAMES, LINK_NAMES
from stylesync.session import Session

DUE_UP_M = ANKLE_HEIGHT_M + 0.03  # an ankle this high is 3 cm off the ground [m]


def landings(clip: str, seed: int, duration_s: float, window_s: float) -> str:
    """One line of figures for a run of ``clip`` with sensor seed ``seed``."""
    ankle = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
    hip = {s: JOINT_NAMES.index(f"{s}_hip") for s in ("left", "right")}
    ticks: list[tuple[float, float, bool, bool]] = []  # time [s], ankle height [m], due, hip at its limit

    def on_tick_for(session: Session):
        def on_tick(state, ref) -> None:
            tau = session.controller.torques(None).values
            for side, target in (ref.recovery_ankle_world or {}).items():
                k = hip[side]
                ticks.append((state.time_s, float(state.link_origin_world[ankle[side]][2]),
                              recovery_landing_due(target),
                              bool(np.any(np.abs(tau[k]) >= 0.999 * TORQUE_LIMIT[k, 0]))))
        return on_tick

    result, planned_s, _ = run_suite_clip(clip, seed, duration_s, on_tick_for)
    end_s = result.fall_time_s if result.fell and result.fall_time_s is not None else planned_s
    seen = [t for t in ticks if t[0] >= end_s - window_s] if result.fell else ticks
    head = f"{clip} seed {seed}: " + (f"fell at {end_s:.2f} s, last {window_s:.1f} s" if result.fell
                                     else f"completed {end_s:.1f} s, whole run")
    if not seen:
        return head + ": no step of its own"
    return (f"{head}: own ticks {len(seen)}, max z {max(t[1] for t in seen):.3f} m, "
            f"due, up {sum(1 for t in seen if t[2] and t[1] > DUE_UP_M)}, hip limit {sum(1 for t in seen if t[3])}")


def _window_argument(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--window", type=float, default=1.5, help="seconds before a fall looked at [s]")


def main() -> None:
    runs_main(__doc__, lambda clip, seed, args: landings(clip, seed, args.duration, args.window), "run:14",
              _window_argument)


if __name__ == "__main__":
    main()

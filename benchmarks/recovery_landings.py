"""When recovery steps touch down, against when their landing is planned for (prints figures; a tool, not a test).

    python benchmarks/recovery_landings.py [--clips 131_01,08_07,jog] [--seeds 4] [--duration 12]

A recovery step (motion/recovery_step.py) plans its landing, each tick, where the capture point will be at the end
of its swing: the nominal one (``MotionConfig.recovery_swing_s``), shortened while the capture landing runs out of
the leg's reach (``recovery_swing_min_s``). Each run of the development suite's clips (as the suite runs them: the
Kinect sensor model with the seed, a recorded file started in its first pose and held for the rest after its end) is
watched through the stepper's ``swing_target``. For every recovery step it records:

    duration     from its first swing tick to its last (the stance FSM ends it on the foot's contact) [s]
    planned      its swing time as planned on its last tick (the nominal one, or shortened) [s]
    overshoot    how far the capture point, on the step's last tick, is beyond the landing capture point predicted
                 on its first tick (for the swing time planned then), along the predicted direction of travel (> 0:
                 it ran on further) [m]

Steps begun from double stance and swings taken over in the air are reported apart, and the first by duration.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np

from stylesync.metrics.dev_suite import clip_specs, suite_config
from stylesync.motion.recovery_step import capture_point
from stylesync.session import Session
from stylesync.sources.registry import open_source

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
CLIPS = "131_01,131_02,08_07,stealthy_walk,zombie_walk,07_11,08_08,10_04,09_06,09_11,jog,run,131_03,dance_b"
DURATION_BINS_S = (0.0, 0.22, 0.25, 0.3, np.inf)


def watch_steps(session: Session) -> list[dict]:
    """Wrap the session's recovery stepper so that each step's duration and overshoot are appended to the list
    returned (on the step's end)."""
    stepper = session.motion.recovery
    steps: list[dict] = []
    plan_target, plan_end = stepper.swing_target, stepper.end

    record: dict = {}  # the step under way (its object, its first capture point and predicted landing one)

    def swing_target(time_s, com_world, com_vel_world, stance_ankle_world, stance_foot_quat_wxyz, heading_world,
                     walk_on=None):
        step = stepper.step
        elapsed_s = time_s - step.start_s
        xi, _ = capture_point(com_world, com_vel_world, stepper.g)
        target = plan_target(time_s, com_world, com_vel_world, stance_ankle_world, stance_foot_quat_wxyz,
                             heading_world, walk_on)
        if record.get("step") is not step:  # its first tick: where the landing is planned for
            remaining_s = max(step.duration_s - elapsed_s, 0.0)
            _, xi_land = stepper.capture_landing(remaining_s, com_world, com_vel_world, stance_ankle_world,
                                                 stance_foot_quat_wxyz, heading_world, step.side, walk_on)
            record.clear()
            record.update(step=step, taken_over=step.taken_over, xi0=xi[:2].copy(),
                          predicted=np.asarray(xi_land[:2], dtype=float).copy())
        record["xi"], record["elapsed_s"], record["planned_s"] = xi[:2].copy(), elapsed_s, step.duration_s
        return target

    def end(time_s):
        if stepper.step is not None and record.get("step") is stepper.step:
            travel = record["predicted"] - record["xi0"]
            norm = float(np.linalg.norm(travel))
            direction = travel / norm if norm > 1e-6 else np.zeros(2)
            steps.append({"taken_over": record["taken_over"], "duration_s": record["elapsed_s"],
                          "planned_s": record["planned_s"],
                          "shortened": record["planned_s"] < stepper.cfg.recovery_swing_s,
                          "overshoot_m": float((record["xi"] - record["predicted"]) @ direction)})
        plan_end(time_s)

    stepper.swing_target, stepper.end = swing_target, end
    return steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clips", default=CLIPS, help="comma-separated development-suite clip names")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=12.0)
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    specs = {name: spec for spec, name, _ in clip_specs(MOCAP if MOCAP.exists() else None)}
    steps: list[dict] = []
    for name in args.clips.split(","):
        if name not in specs:
            print(f"{name}: not a clip of the development suite here (is ../shared/mocap there?)")
            continue
        for seed in range(args.seeds):
            opened = open_source(specs[name], seed=seed, duration_s=args.duration)
            cfg, _ = suite_config(specs[name], opened, seed, args.duration)
            session = Session(cfg, opened.source)
            run_steps = watch_steps(session)
            result = session.run()
            opened.source.close()
            steps += run_steps
            outcome = f"fell at {result.fall_time_s:.2f} s" if result.fell else "no fall"
            print(f"{name} seed {seed}: {len(run_steps)} recovery steps, {outcome}")
    for label, taken in (("begun from double stance", False), ("taken over in the air", True)):
        group = [s for s in steps if s["taken_over"] is taken]
        if not group:
            continue
        durations = np.array([s["duration_s"] for s in group])
        overshoot = np.array([s["overshoot_m"] for s in group])
        planned = np.array([s["planned_s"] for s in group])
        shortened = np.array([s["shortened"] for s in group])
        print(f"{label}: {len(group)} steps; duration p10/p50/p90 "
              f"{' / '.join(f'{v:.3f}' for v in np.percentile(durations, [10, 50, 90]))} s; "
              f"overshoot p10/p50/p90 {' / '.join(f'{v:+.3f}' for v in np.percentile(overshoot, [10, 50, 90]))} m; "
              f"{int(shortened.sum())} shortened"
              + (f" (planned p50 {float(np.median(planned[shortened])):.3f} s, lasting p50 "
                 f"{float(np.median(durations[shortened])):.3f} s)" if shortened.any() else ""))
        if taken:
            continue
        for lo, hi in zip(DURATION_BINS_S[:-1], DURATION_BINS_S[1:], strict=True):
            sel = (durations >= lo) & (durations < hi)
            if sel.any():
                print(f"  lasting {lo:.2f}-{hi:.2f} s: {int(sel.sum())} steps, overshoot median "
                      f"{float(np.median(overshoot[sel])):+.3f} m")


if __name__ == "__main__":
    main()

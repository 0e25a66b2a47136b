"""Per swing of one development-suite run: how far the capture point went inwards of the stance sole (prints figures;
a tool for telling a falling swing from an ordinary one).

    python benchmarks/swing_capture.py zombie_walk --seeds 0,2,4 [--min-cm 4] [--duration 12]

For each single stance the character takes over from its operator (not its own recovery steps) it prints when it
began [s], the largest distance of the capture point inwards of the stance sole's inner edge, across the foot (its
frame's y; > 0 beyond the edge, towards the swing foot) [cm], and how long the stance lasted [s]; then whether and
when the run fell. The run is made as the suite makes it (trace_run.resolve, suite_config). Stances whose largest
distance is below ``--min-cm`` are left out.
"""

from __future__ import annotations

import argparse
import logging

import numpy as np
from trace_run import resolve

from stylesync import rotations as rot
from stylesync.metrics.dev_suite import suite_config
from stylesync.model.character import FOOT_WIDTH_M, LINK_NAMES
from stylesync.motion.pose_optimization import _inward_m
from stylesync.motion.recovery_step import capture_point
from stylesync.session import Session
from stylesync.sources.registry import open_source

_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
_UP = np.array([0.0, 0.0, 1.0])


def inward_of_sole_m(point_world: np.ndarray, ankle_world: np.ndarray, foot_yaw_rad: float, stance: str) -> float:
    """Distance of a point beyond the stance sole's inner edge, across the foot (> 0 towards the other foot) [m]:
    the motion stage's own across-the-foot distance from the ankle, less half the sole's width."""
    return _inward_m(point_world, ankle_world, foot_yaw_rad, stance) - FOOT_WIDTH_M / 2


def swings(clip: str, seed: int, duration_s: float) -> tuple[list[dict], float | None]:
    """The operator's single stances the character took in one run (start [s], largest inward distance [m],
    duration [s]) and the fall time [s] (None: no fall)."""
    spec = resolve(clip)
    opened = open_source(spec, seed=seed, duration_s=duration_s)
    cfg, _ = suite_config(spec, opened, seed, duration_s)
    session = Session(cfg, opened.source)
    g = cfg.world.gravity_mps2
    out: list[dict] = []
    current: dict = {}

    def on_tick(state, ref) -> None:
        stance_name = ref.character_stance.name
        if stance_name not in ("LS", "RS") or session.motion.char_fsm.recovery_step:
            current.clear()
            return
        stance = "left" if stance_name == "LS" else "right"
        if current.get("stance") != stance:
            current.clear()
            current.update(stance=stance, start_s=state.time_s, inward_m=-np.inf)
            out.append(current.copy())
        xi, _ = capture_point(session.mass.com(state), session.mass.com_velocity(state), g)
        ankle = _ANKLE[stance]
        yaw = rot.twist_angle(state.link_quat_wxyz[ankle], _UP)
        current["inward_m"] = max(current["inward_m"],
                                  inward_of_sole_m(xi, state.link_origin_world[ankle], yaw, stance))
        current["duration_s"] = state.time_s - current["start_s"]
        out[-1] = current.copy()

    session.on_tick = on_tick
    try:
        result = session.run()
    finally:
        opened.source.close()
    return out, (result.fall_time_s if result.fell else None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", help="a development-suite clip name or a source spec")
    ap.add_argument("--seeds", default="0", help="comma-separated sensor seeds")
    ap.add_argument("--duration", type=float, default=12.0, help="at most this long, the rest included [s]")
    ap.add_argument("--min-cm", type=float, default=4.0, help="leave out stances below this largest distance [cm]")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    for seed in (int(s) for s in args.seeds.split(",")):
        found, fall_s = swings(args.clip, seed, args.duration)
        shown = [w for w in found if 100.0 * w["inward_m"] >= args.min_cm]
        print(f"{args.clip} seed {seed}: " + ("no fall" if fall_s is None else f"fell at {fall_s:.2f} s"))
        for w in shown:
            print(f"  {w['start_s']:6.2f} s  {w['stance']:>5} stance  capture point {100.0 * w['inward_m']:5.1f} cm "
                  f"inwards of the sole  for {w.get('duration_s', 0.0):.2f} s")


if __name__ == "__main__":
    main()

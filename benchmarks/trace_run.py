"""Per-tick balance trace of one run of the development suite: what the character stood on, where its capture
point was, what the COM task asked for and what the body did (prints figures; a tool for explaining a fall).

    python benchmarks/trace_run.py 05_01 --seed 0 [--from 4.5] [--to 7] [--every 6] [--duration 12] [--past-fall]
                                         [--feet] [--yaw] [--follow-path] [--heights]

The clip is a development-suite name (`stylesync bench --suite dev`: a humanoid3d clip or a file of ../shared/mocap)
or a source spec (``bvh:PATH``, ``builtin:walk``), run as the suite runs it: the Kinect sensor model with the seed,
a recorded file started in its first pose and held for the rest after its end. Columns, world frame, metres:

    t          simulated time [s]
    op/ch      the operator's and the character's stance (DS, LS, RS); ``+own`` a recovery step, ``+held`` a late
               contact holding the reference
    com, v     the COM and its velocity (horizontal) [m, m/s]
    z, z tgt   the COM's height and the COM target's [m]
    xi out     the capture point's signed distance from the support polygon of the soles on the ground (> 0
               outside) [m]
    tgt, vtgt  the COM target and its velocity after the motion stage (capture bound included) [m, m/s]
    F asked    the COM task's horizontal force (Eq. 16 with the LIPM term, limited to what the support can give) [N]
    m a        the horizontal force the body actually took (mass times the COM's acceleration between ticks) [N]
    fL fR      the soles' normal forces [N]
    --yaw      the headings [deg]: the reference's root (``ref``), the character's pelvis (``ch``) and feet (``ftL``,
               ``ftR``)
    --heights  the ankles' heights (``zL``, ``zR``) and, in a step of the character's own, the swing ankle's target
               (``own``) [m]
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
from collections.abc import Callable
from pathlib import Path

import numpy as np

from stylesync import rotations as rot
from stylesync.config import follow_path, pelvis_joint
from stylesync.metrics.dev_suite import clip_specs, suite_config
from stylesync.model.character import LINK_NAMES
from stylesync.model.sole import convex_hull_xy, outside_distance_m, sole_corners_world
from stylesync.motion.recovery_step import capture_point, soles_on_ground
from stylesync.session import Session, SessionResult
from stylesync.sources.registry import open_source

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}


def resolve(clip: str) -> str:
    """A suite clip's source spec, or ``clip`` itself when it is already a spec."""
    if ":" in clip:
        return clip
    specs = {name: spec for spec, name, _ in clip_specs(MOCAP if MOCAP.exists() else None)}
    if clip not in specs:
        raise SystemExit(f"no clip '{clip}' in the development suite; clips: {', '.join(sorted(specs))}")
    return specs[clip]


def run_suite_clip(clip: str, seed: int, duration_s: float,
                   on_tick_for: Callable[[Session], Callable]) -> tuple[SessionResult, float, float]:
    """Run ``clip`` with sensor seed ``seed`` as the development suite runs it, ``on_tick_for(session)`` called on
    each control tick; the result, the run's planned duration [s] and the time his clip ends [s]."""
    spec = resolve(clip)
    opened = open_source(spec, seed=seed, duration_s=duration_s)
    cfg, clip_end_s = suite_config(spec, opened, seed, duration_s)
    session = Session(cfg, opened.source)
    session.on_tick = on_tick_for(session)
    try:
        return session.run(), cfg.duration_s, clip_end_s
    finally:
        opened.source.close()


def runs_main(doc: str, figures: Callable[[str, int, argparse.Namespace], str], example: str,
              add_arguments: Callable[[argparse.ArgumentParser], None] = lambda ap: None) -> None:
    """The command line of a script that prints one line of ``figures(clip, seed, args)`` per CLIP:SEED run."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help=f"CLIP:SEED, e.g. {example}")
    add_arguments(ap)
    ap.add_argument("--duration", type=float, default=12.0, help="the run's length [s]")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    for run in args.runs:
        clip, _, seed = run.rpartition(":")
        print(figures(clip, int(seed), args), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", help="a development-suite clip name or a source spec")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--duration", type=float, default=12.0, help="at most this long, the rest included [s]")
    ap.add_argument("--from", dest="t0", type=float, default=0.0, help="first time printed [s]")
    ap.add_argument("--to", dest="t1", type=float, default=float("inf"),
                    help="last time printed; the run ends there [s]")
    ap.add_argument("--every", type=int, default=6, help="print every this many control ticks (and each change "
                                                          "of stance)")
    ap.add_argument("--feet", action="store_true", help="also print the ankles' horizontal positions [m]")
    ap.add_argument("--yaw", action="store_true", help="also print the headings of the reference's root, the "
                                                        "character's pelvis and its feet [deg]")
    ap.add_argument("--follow-path", action="store_true", help="with --follow-path's settings (config.follow_path)")
    ap.add_argument("--pelvis-joint", action="store_true", help="with --pelvis-joint's settings (config.pelvis_joint)")
    ap.add_argument("--heights", action="store_true", help="also print the ankles' heights and, in a step of the "
                                                           "character's own, its ankle target [m]")
    ap.add_argument("--past-fall", action="store_true", help="run on after the first fall (to see what follows it)")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    spec = resolve(args.clip)
    opened = open_source(spec, seed=args.seed, duration_s=args.duration)
    cfg, clip_end = suite_config(spec, opened, args.seed, args.duration)
    if args.follow_path:
        cfg = follow_path(cfg)
    if args.pelvis_joint:
        cfg = pelvis_joint(cfg)
    length = cfg.duration_s
    session = Session(dataclasses.replace(cfg, duration_s=min(length, args.t1)), opened.source)
    session.stop_on_fall = not args.past_fall
    mass_kg = session.mass.total_kg
    g = cfg.world.gravity_mps2
    last: dict = {"v": None, "t": None, "key": None, "n": 0}
    print(f"{spec}, seed {args.seed}: the clip ends at {clip_end:.2f} s, the run at {length:.2f} s")
    print(f"{'t':>6} {'op':>3} {'ch':>8} {'com':>13} {'v':>13} {'z':>5} {'z tgt':>5} {'xi out':>7} {'tgt':>13} "
          f"{'vtgt':>13} {'F asked':>11} {'m a':>11} {'fL':>5} {'fR':>5}")

    def on_tick(state, ref) -> None:
        com, vel = session.mass.com(state), session.mass.com_velocity(state)
        accel = (vel - last["v"]) / (state.time_s - last["t"]) if last["v"] is not None else np.zeros(3)
        last["v"], last["t"] = vel.copy(), state.time_s
        if not args.t0 <= state.time_s <= args.t1:
            return
        motion = session.motion
        reading = motion.reading
        flags = ("+own" if motion.char_fsm.recovery_step else "") + ("+held" if reading.held else "")
        key = (reading.operator_stance.name, ref.character_stance.name, flags)
        last["n"] += 1
        if key == last["key"] and last["n"] % args.every:
            return
        last["key"] = key
        xi, _ = capture_point(com, vel, g)
        corners = [sole_corners_world(state.link_origin_world[_ANKLE[s]], state.link_quat_wxyz[_ANKLE[s]])[:, :2]
                   for s in soles_on_ground(state)]
        out = outside_distance_m(xi, convex_hull_xy(np.vstack(corners)))[0] if corners else float("nan")
        force = session.controller.telemetry.com_force_n
        taken = mass_kg * accel
        fl, fr = (state.foot_contact_force_n[f"{s}_ankle"] for s in ("left", "right"))
        print(f"{state.time_s:6.2f} {key[0]:>3} {key[1] + flags:>8} ({com[0]:+5.2f},{com[1]:+5.2f}) "
              f"({vel[0]:+5.2f},{vel[1]:+5.2f}) {com[2]:5.2f} {ref.com_world[2]:5.2f} {out:+7.3f} "
              f"({ref.com_world[0]:+5.2f},{ref.com_world[1]:+5.2f}) "
              f"({ref.com_vel_world[0]:+5.2f},{ref.com_vel_world[1]:+5.2f}) ({force[0]:+4.0f},{force[1]:+4.0f}) "
              f"({taken[0]:+4.0f},{taken[1]:+4.0f}) {fl:5.0f} {fr:5.0f}"
              + ("".join(f" {s[0]}({state.link_origin_world[_ANKLE[s]][0]:+5.2f},"
                         f"{state.link_origin_world[_ANKLE[s]][1]:+5.2f})" for s in ("left", "right"))
                 if args.feet else "")
              + (" yaw ref {:+5.0f} ch {:+5.0f} ftL {:+5.0f} ftR {:+5.0f}".format(
                  *np.degrees([rot.yaw_from_quat(ref.root_quat_wxyz), rot.yaw_from_quat(state.root_quat_wxyz),
                               *(rot.yaw_from_quat(state.link_quat_wxyz[_ANKLE[s]]) for s in ("left", "right"))]))
                 if args.yaw else "")
              + (" zL {:.3f} zR {:.3f}".format(*(state.link_origin_world[_ANKLE[s]][2] for s in ("left", "right")))
                 + "".join(f" own {s[0]}({p[0]:+5.2f},{p[1]:+5.2f},{p[2]:.3f})"
                           for s, p in (ref.recovery_ankle_world or {}).items())
                 if args.heights else ""))

    session.on_tick = on_tick
    try:
        result = session.run()
    finally:
        opened.source.close()
    where = ("" if not result.fell else
             " (in the rest after the clip)" if (result.fall_time_s or 0.0) >= clip_end else " (during the clip)")
    print(f"fell: {result.fell}" + (f" at {result.fall_time_s:.2f} s{where}" if result.fell else ""))


if __name__ == "__main__":
    main()

"""Speed of the whole pipeline against physics alone, measured in one run (prints figures; not a test).

    python benchmarks/bench_pipeline.py [--clip stand] [--duration 20] [--repeat 3] [--motion-ahead]

Physics alone, two ways: the same world and character stepped at the physics rate with zero joint torques (the
character falls and lies on the ground, where the engine's contact work is about twice a standing or walking body's:
135-160 against 65-70 µs a step on the walk), and the pipeline run's own engine calls replayed on a new engine (its
resets, ground moves and torques, step by step, without the controller: the same trajectory, at the engine's cost
alone; the replay's end is checked against the run's). Whole pipeline: source -> processing -> motion -> control ->
physics, headless, as fast as possible, as `stylesync demo` runs it: the operator side (source, processing, style
features) computed ahead in a second process (prefetch.py). The pipeline is also timed with everything in one
process, and with ``--motion-ahead`` as `stylesync demo --motion-ahead` runs it too: the motion stage on the last
tick's state, computed a tick ahead in a third process (motion_ahead.py; another simulation). All are timed
alternately (--repeat times each), and their medians and per-round ratios are printed: the ratio is meaningful on a
noisy machine even when the absolute figures are not.
"""

from __future__ import annotations

import argparse
import logging
import time

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.metrics.bench import physics_only_rtf
from stylesync.session import Session, SessionResult
from stylesync.sim.factory import make_backend
from stylesync.sources.builtin_operator import builtin_operator

# The engine calls that change the world, recorded in a pipeline run and replayed in order
_WORLD_CALLS = ("reset", "set_velocities", "_keep_ground_under", "apply_torques", "step")


def _record_world_calls(backend) -> list[tuple[str, tuple]]:
    """Wrap ``backend``'s world-changing methods so that each call is appended, with its arguments, to the list
    returned (reads do not change the world: read_state's ground move is recorded as its own call)."""
    calls: list[tuple[str, tuple]] = []
    for name in _WORLD_CALLS:
        method = getattr(backend, name)

        def recorded(*args, _name=name, _method=method):
            calls.append((_name, args))
            return _method(*args)

        setattr(backend, name, recorded)
    return calls


def replayed_physics_rtf(cfg: SessionConfig, calls: list[tuple[str, tuple]], sim_s: float) -> tuple[float, np.ndarray]:
    """Realtime factor of the engine alone on a recorded run's trajectory: its calls replayed on a new engine
    (timed from the first to the last), and the root's final position [m] (to check that the replay went the
    run's way)."""
    backend = make_backend(cfg.world, cfg.clocks.physics_hz)
    t0 = time.perf_counter()
    for name, args in calls:
        getattr(backend, name)(*args)
    wall = time.perf_counter() - t0
    root = backend.read_state(sim_s).root_pos_world.copy()
    backend.close()
    return sim_s / wall, root


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clip", default="stand")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds of each measurement")
    ap.add_argument("--repeat", type=int, default=3,
                    help="alternating measurements of each (physics alone, pipeline); medians are reported")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--motion-ahead", action="store_true", help="also the pipeline with the motion stage a tick ahead")
    args = ap.parse_args()
    logging.getLogger("stylesync").setLevel(logging.ERROR)  # the runs' warnings (movement bounds) are not measured here
    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, operator=OperatorConfig(clip=args.clip))
    phys_rtfs, rtfs, one_rtfs, ahead_rtfs = [], [], [], []
    result = ahead = None

    replay_rtfs: list[float] = []
    replay_gap_m: list[float] = []

    def pipeline(prefetch: bool, motion_ahead: bool = False, replay: bool = False) -> SessionResult:
        run_cfg = cfg.replace(motion_ahead=motion_ahead)
        source, _ = builtin_operator(run_cfg.operator, run_cfg.clocks, run_cfg.duration_s + 1.0, run_cfg.seed)
        session = Session(run_cfg, source)
        session.prefetch_operator = prefetch
        calls = _record_world_calls(session.backend) if replay else None
        run = session.run()
        if calls is not None:
            end = session.backend.read_state(run.sim_duration_s).root_pos_world.copy()
            rtf_replay, root = replayed_physics_rtf(run_cfg, calls, run.sim_duration_s)
            replay_rtfs.append(rtf_replay)
            replay_gap_m.append(float(np.linalg.norm(root - end)))
        return run

    for _ in range(max(args.repeat, 1)):  # alternated, so that all see the machine's slow and fast spells alike
        phys_rtfs.append(physics_only_rtf(cfg, args.duration))
        one = pipeline(prefetch=False)
        one_rtfs.append(one.sim_duration_s / one.wall_duration_s)
        result = pipeline(prefetch=True, replay=True)
        rtfs.append(result.sim_duration_s / result.wall_duration_s)
        if args.motion_ahead:
            ahead = pipeline(prefetch=True, motion_ahead=True)
            ahead_rtfs.append(ahead.sim_duration_s / ahead.wall_duration_s)
    assert result is not None
    phys, rtf, one_rtf = float(np.median(phys_rtfs)), float(np.median(rtfs)), float(np.median(one_rtfs))
    ratios = [r / p for r, p in zip(rtfs, phys_rtfs, strict=True)]
    one_ratios = [r / p for r, p in zip(one_rtfs, phys_rtfs, strict=True)]
    ticks = len(result.stage_ms["motion"])
    steps = len(result.stage_ms["physics"])
    print(f"clip {args.clip}, simulated {result.sim_duration_s:.2f} s"
          f"{f' (fell at {result.fall_time_s:.2f} s)' if result.fell else ''}, {ticks} control ticks, "
          f"{steps} physics steps, {len(rtfs)} alternating measurements of each")
    print(f"realtime factor, physics alone:  {phys:6.2f}x median   ({', '.join(f'{x:.2f}' for x in phys_rtfs)})")
    print(f"realtime factor, whole pipeline: {rtf:6.2f}x median   ({', '.join(f'{x:.2f}' for x in rtfs)})"
          f"{'' if result.operator_prefetched else '   (operator side NOT prefetched: see prefetch.py)'}")
    print(f"  ... in one process:            {one_rtf:6.2f}x median   ({', '.join(f'{x:.2f}' for x in one_rtfs)})")
    print(f"ratio pipeline / physics alone:  {float(np.median(ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in ratios)})")
    print(f"  ... in one process:            {float(np.median(one_ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in one_ratios)})")
    replay_ratios = [r / p for r, p in zip(rtfs, replay_rtfs, strict=True)]
    gap_m = max(replay_gap_m)
    end = "where the run's did" if gap_m == 0.0 else f"{gap_m * 1e3:.3f} mm from the run's"
    print(f"realtime factor, the run's engine calls replayed: {float(np.median(replay_rtfs)):6.2f}x median   "
          f"({', '.join(f'{x:.2f}' for x in replay_rtfs)}; its root ends {end})")
    print(f"ratio pipeline / the run's own physics: {float(np.median(replay_ratios)):6.2f} median   "
          f"({', '.join(f'{x:.2f}' for x in replay_ratios)})")
    if ahead is not None:
        ahead_ratios = [r / p for r, p in zip(ahead_rtfs, phys_rtfs, strict=True)]
        print(f"  ... the motion stage ahead:    {float(np.median(ahead_ratios)):6.2f} median   "
              f"({', '.join(f'{x:.2f}' for x in ahead_ratios)}); {float(np.median(ahead_rtfs)):.2f}x median; "
              f"motion / control update in the main process {np.mean(ahead.stage_ms['motion']):.3f} / "
              f"{np.mean(ahead.stage_ms['control_update']):.3f} ms a tick at the mean")
    print("time per control tick in the main process [ms], mean / p99 (last pipeline measurement):")
    per_tick = {k: np.asarray(v) for k, v in result.stage_ms.items()}
    steps_per_tick = steps / max(ticks, 1)
    for name, values in per_tick.items():
        if values.size == 0:
            continue
        scale = steps_per_tick if name in ("torques", "physics") else 1.0  # per-step stages summed over a tick
        print(f"  {name:15s} {values.mean() * scale:7.3f} / {np.percentile(values, 99) * scale:7.3f}"
              f"{f'   ({steps_per_tick:.1f} physics steps per tick)' if scale != 1.0 else ''}")
    tick_total = result.log.array("tick_ms")
    print(f"  {'control tick':15s} {tick_total.mean():7.3f} / {np.percentile(tick_total, 99):7.3f}"
          "   (processing + motion + control update)")


if __name__ == "__main__":
    main()

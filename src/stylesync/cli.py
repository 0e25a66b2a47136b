"""Command line: ``stylesync demo``, ``run``, ``measure``, ``replay``."""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import secrets
import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from stylesync import cli_args as typed
from stylesync.config import (
    SHARED_DIR,
    START_RAMPS,
    VIEWER_DRAW_HZ,
    ClockConfig,
    ControlConfig,
    OperatorConfig,
    SessionConfig,
    damp_angular_momentum,
    follow_path,
    free_swing,
    in_place,
    late_contact_steps,
    no_track_rise,
    pelvis_joint,
)
from stylesync.errors import ConfigError, SourceError, StylesyncError
from stylesync.files import write_atomically

if TYPE_CHECKING:
    from stylesync.export.session_file import SessionFile

_HEADLINE = ("fell", "fall_time_s", "sim_duration_s", "operator_steps", "character_steps", "realtime_factor")


class _Progress:
    """One status line on stderr: simulated time, realtime factor, falls (at most twice a second)."""

    def __init__(self, duration_s: float):
        self.duration_s, self._last = duration_s, -1.0

    def __call__(self, sim_s: float, wall_s: float) -> None:
        if wall_s - self._last < 0.5:
            return
        self._last = wall_s
        done = int(30 * sim_s / self.duration_s)
        print(f"\r[{'#' * done}{'.' * (30 - done)}] {sim_s:6.2f}/{self.duration_s:.2f} s sim, "
              f"{sim_s / max(wall_s, 1e-9):4.1f}x real time", end="", file=sys.stderr, flush=True)

    def done(self, fell: bool, fall_time_s: float | None) -> None:
        status = f"fell at {fall_time_s:.2f} s" if fell and fall_time_s is not None else "no fall"
        print(f"\r{status:<70}", file=sys.stderr)


def _run_session(cfg: SessionConfig, source, out: Path, extra: dict, args: argparse.Namespace) -> int:
    from stylesync.export.session_file import SessionRecorder
    from stylesync.metrics.plots import write_plots, write_strip
    from stylesync.metrics.summary import summarize
    from stylesync.session import Session

    out.mkdir(parents=True, exist_ok=True)
    record = Path(args.record) if args.record else out / "session.jsonl"
    _clear_outputs(out, record)
    session = Session(cfg, source)
    run_id = secrets.token_hex(8)  # in the session file's header, metrics.json and the report
    # A run as fast as possible writes its session file when it ends (session_file.py): not in the control loop.
    recorder = SessionRecorder(record, cfg, session, deferred=not cfg.realtime, run_id=run_id,
                               wall_clock=cfg.realtime)
    session.on_tick = recorder.tick
    viewer = None
    if args.viewer != "none":
        from stylesync.viewer.attach import chain, open_viewer, session_hook

        viewer = open_viewer(args.viewer, session, args.viewer_host, args.viewer_port, args.viewer_hz)
        session.on_tick = chain(recorder.tick, session_hook(session, viewer, args.viewer_hz))
        print(f"viewer: {viewer.url}", flush=True)
    # A fall is recorded; asked to go on, or watched (Reset stands the character up), the run does not end there.
    session.stop_on_fall = not (args.continue_after_fall or viewer is not None)
    session.finish_on_interrupt = True  # Ctrl-C ends the run with its outputs written (exit 130)
    show = args.progress or sys.stderr.isatty()
    progress = _Progress(cfg.duration_s) if show else None
    metrics: dict | None = None
    try:
        result = session.run(progress=progress, render_every_s=max(cfg.duration_s / 8, 0.25))
        metrics = summarize(result) | extra | {"run_id": run_id}
    except KeyboardInterrupt:
        session.closed = True
        raise
    finally:
        source.close()
        recorder.close(metrics)
        if viewer is not None:
            _hold_viewer(viewer)
    if progress is not None:
        progress.done(result.fell, result.fall_time_s)
    metrics["session_file"] = str(record)
    write_atomically(out / "metrics.json", json.dumps(metrics, indent=2))
    if args.export_bvh or args.export_mp4:
        _export(record, args.export_bvh, args.export_mp4)
    write_plots(result, out)
    write_strip(session.renders, out / "render_strip.png")
    session.release_engine()
    print(json.dumps({k: metrics[k] for k in _HEADLINE}))
    from stylesync.metrics.report import write_report

    write_report(out)
    print(f"outputs in {out} (report.html)")
    if result.end_reason == "interrupted":
        print("stylesync: interrupted", file=sys.stderr)
        return 130
    return 0


RUN_OUTPUTS = ("metrics.json", "report.html", "com_footsteps.png", "stance_states.png", "style_features.png",
               "render_strip.png", "session.jsonl")


def _clear_outputs(out: Path, record: Path) -> None:
    """Remove an earlier run's outputs from ``out`` (and the session file about to be written), so that a run cut
    short never leaves another run's metrics or report beside its own session file."""
    for path in [out / name for name in RUN_OUTPUTS] + [record]:
        if path.is_file():
            path.unlink()


def _hold_viewer(viewer) -> None:
    """Keep the viewer up after the run until Ctrl-C when a person is at the terminal."""
    try:
        if sys.stdin.isatty():
            import time

            print(f"run finished; the viewer stays at {viewer.url} (Ctrl-C to quit)", file=sys.stderr, flush=True)
            while True:
                time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()


def _replay_viewer(args: argparse.Namespace, session) -> None:
    import time

    from stylesync.export.replay import resample_ticks
    from stylesync.viewer.attach import open_viewer, replay_snapshots

    viewer = open_viewer(args.viewer, None, args.viewer_host, args.viewer_port, args.viewer_hz)
    print(f"viewer: {viewer.url}", flush=True)
    ticks = resample_ticks(session, args.viewer_hz)
    wall0 = time.perf_counter()
    t0 = ticks[0]["t"] if ticks else 0.0
    try:
        for snap in replay_snapshots(ticks, session.header.get("operator_joints", [])):
            lag = (snap.time_s - t0) / args.speed - (time.perf_counter() - wall0)
            if lag > 0:
                time.sleep(lag)
            viewer.publish(snap)
        time.sleep(2.0 / args.viewer_hz)
    finally:
        _hold_viewer(viewer)


def _demo(args: argparse.Namespace) -> int:
    from stylesync.sources.builtin_operator import builtin_operator

    operator = OperatorConfig(clip=args.clip, turn_rate_rad_s=args.turn_rate, mirror=args.mirror,
                              start_ramp=args.start_ramp)
    cfg = SessionConfig(duration_s=args.duration, seed=args.seed, gui=args.gui,
                        realtime=args.realtime or args.viewer != "none", operator=operator,
                        control=ControlConfig(lipm_time_sync=not args.no_lipm), motion_ahead=args.motion_ahead)
    cfg = _motion_options(cfg, args)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    return _run_session(cfg, source, Path(args.out), {"clip": args.clip, "turn_rate_rad_s": args.turn_rate,
                                                      "start_ramp": args.start_ramp,
                                                      "lipm_time_sync": not args.no_lipm,
                                                      "mirror": args.mirror,
                                                      "follow_path": args.follow_path,
                                                      "in_place": args.in_place,
                                                      "free_swing": args.free_swing,
                                                      "late_contact_steps": args.late_contact_steps,
                                                      "pelvis_joint": args.pelvis_joint,
                                                      "track_rise": not args.no_track_rise,
                                                      "motion_ahead": args.motion_ahead}, args)


def _suite_operator(args: argparse.Namespace) -> OperatorConfig:
    """The dev suite's operator: the default, or his mirror image (--mirror) and a noisier sensor (--sensor-noise)."""
    default = OperatorConfig()
    return OperatorConfig(mirror=args.mirror, position_noise_m=default.position_noise_m * args.sensor_noise,
                          orientation_noise_rad=default.orientation_noise_rad * args.sensor_noise)


def _motion_options(cfg: SessionConfig, args: argparse.Namespace) -> SessionConfig:
    """``cfg`` with the options asked for on the command line (--in-place, --follow-path, --free-swing,
    --late-contact-steps, --pelvis-joint, --no-track-rise, --damp-angular-momentum)."""
    if args.in_place and args.follow_path:
        raise ConfigError("--in-place and --follow-path contradict each other: give one of them")
    if args.in_place:
        cfg = in_place(cfg)
    if args.follow_path:
        cfg = follow_path(cfg)
    if args.free_swing:
        cfg = free_swing(cfg)
    if args.late_contact_steps:
        cfg = late_contact_steps(cfg)
    if args.pelvis_joint:
        cfg = pelvis_joint(cfg)
    if args.no_track_rise:
        cfg = no_track_rise(cfg)
    if args.damp_angular_momentum:
        cfg = damp_angular_momentum(cfg)
    return cfg


def _open(args: argparse.Namespace, clocks: ClockConfig, duration_s: float | None):
    from stylesync.sources.registry import open_source

    return open_source(args.source, clocks=clocks, sensor=args.sensor, seed=args.seed, duration_s=duration_s,
                       joint_map=args.joint_map, bvh_scale_m=args.bvh_scale, bvh_up_axis=args.bvh_up)


def _run(args: argparse.Namespace) -> int:
    clocks = ClockConfig()
    opened = _open(args, clocks, args.duration)
    live = opened.duration_s is None
    if live and args.duration is None:
        raise ConfigError("a live source needs --duration (seconds to run)")
    duration = args.duration if args.duration is not None else float(opened.duration_s or 0.0)
    if not live and opened.duration_s is not None and duration > opened.duration_s:
        print(f"stylesync: the recording ends (with its rest) at {opened.duration_s:.2f} s: the run stops there",
              file=sys.stderr)
        duration = float(opened.duration_s)
    cfg = SessionConfig(duration_s=duration, seed=args.seed, gui=args.gui, stream_timeout_s=args.stream_timeout,
                        realtime=args.realtime or live or args.viewer != "none",
                        clocks=dataclasses.replace(clocks, mocap_hz=opened.mocap_hz),
                        control=ControlConfig(lipm_time_sync=not args.no_lipm),
                        operator=OperatorConfig(mirror=args.mirror), motion_ahead=args.motion_ahead)
    cfg = _motion_options(cfg, args)
    return _run_session(cfg, opened.source, Path(args.out), {"source": args.source, "sensor": opened.sensor,
                                                              "lipm_time_sync": not args.no_lipm,
                                                              "mirror": args.mirror,
                                                              "follow_path": args.follow_path,
                                                              "in_place": args.in_place,
                                                              "free_swing": args.free_swing,
                                                              "late_contact_steps": args.late_contact_steps,
                                                              "pelvis_joint": args.pelvis_joint,
                                                              "track_rise": not args.no_track_rise,
                                                              "motion_ahead": args.motion_ahead,
                                                              **opened.extras}, args)


def _export(record: Path | SessionFile, bvh: str | None, mp4: str | None) -> None:
    from stylesync.export.replay import export_bvh, export_mp4
    from stylesync.export.session_file import read_session

    session = read_session(record) if isinstance(record, Path) else record
    if not session.ticks:
        raise SourceError("the session has no ticks to export (the run was cut short before its first one)")
    for path in (bvh, mp4):
        if path:
            Path(path).expanduser().absolute().parent.mkdir(parents=True, exist_ok=True)
    if bvh:
        n = export_bvh(session, bvh)
        print(f"BVH: {bvh} ({n} frames)")
    if mp4:
        n = export_mp4(session, mp4)
        print(f"MP4: {mp4} ({n} frames)")


def _replay(args: argparse.Namespace) -> int:
    from stylesync.export.session_file import read_session

    session = read_session(args.file)
    print(json.dumps({"ticks": len(session.ticks), "duration_s": session.ticks[-1]["t"] if session.ticks else 0.0,
                      "fell": (session.metrics or {}).get("fell")}))
    if not (args.export_bvh or args.export_mp4 or args.viewer != "none"):
        raise ConfigError("replay: give --viewer web|gui, --export-bvh FILE and/or --export-mp4 FILE")
    if not session.ticks:
        raise SourceError(f"{args.file}: no ticks to replay (the run was cut short before its first one)")
    if args.export_bvh or args.export_mp4:
        _export(session, args.export_bvh, args.export_mp4)
    if args.viewer != "none":
        _replay_viewer(args, session)
    return 0


def _bench(args: argparse.Namespace) -> int:
    from stylesync.metrics.bench import run_bench

    shared = Path(args.shared) if args.shared else SHARED_DIR
    if args.suite == "dev":
        from stylesync.metrics.dev_suite import (
            FOLLOW_PATH_VERSION,
            IN_PLACE_VERSION,
            ORDER,
            PELVIS_JOINT_VERSION,
            SUITE_CONTROLLERS,
            clip_specs,
            run_dev_suite,
            user_clip_specs,
        )

        only = tuple(c.strip() for c in args.only.split(",") if c.strip()) if args.only else ()
        unknown = [c for c in only if c not in ORDER]
        if unknown:
            raise ConfigError(f"unknown categories {', '.join(unknown)}; expected some of {', '.join(ORDER)}")
        mocap = shared / "mocap" if (shared / "mocap").is_dir() else None
        # the follow-path and in-place versions beside stylesync's (the first), before the baselines
        versions = tuple(v for v, given in ((FOLLOW_PATH_VERSION, args.follow_path), (IN_PLACE_VERSION, args.in_place),
                                            (PELVIS_JOINT_VERSION, args.pelvis_joint)) if given)
        controllers = (*SUITE_CONTROLLERS[:1], *versions, *SUITE_CONTROLLERS[1:])
        if args.clips_only and not args.clips:
            raise ConfigError("--clips-only needs --clips")
        own = [spec for given in args.clips or () for spec in user_clip_specs(given)]
        clips = own if args.clips_only else [*clip_specs(mocap), *own]
        report = run_dev_suite(Path(args.out), args.seeds, args.duration, mocap, only,
                               controllers=controllers, workers=args.workers, executor=args.executor,
                               first_seed=args.seed, operator=_suite_operator(args), clips=clips)
    else:
        for flag, given in (("--clips", bool(args.clips)), ("--clips-only", args.clips_only),
                            ("--mirror", args.mirror), ("--sensor-noise", args.sensor_noise != 1.0),
                            ("--follow-path", args.follow_path), ("--in-place", args.in_place),
                            ("--pelvis-joint", args.pelvis_joint)):
            if given:
                raise ConfigError(f"{flag} is a dev-suite option: use it with --suite dev")
        report = run_bench(Path(args.out), args.duration, args.seed, shared if shared.is_dir() else None,
                           executor=args.executor or "inline", workers=args.workers)
    print(report["table"])
    from stylesync.metrics.report import write_report

    print(f"outputs in {args.out}; report: {write_report(args.out)}")
    return 0


def _experiment(args: argparse.Namespace) -> int:
    import importlib

    from stylesync.metrics.report import write_report

    run = importlib.import_module(f"stylesync.experiments.{args.name.replace('-', '_')}").run
    out = Path(args.out) / args.name
    holds, summary = run(out, args.duration, args.seed)
    print(json.dumps(summary))
    print(f"claim {'holds' if holds else 'does NOT hold'}; report: {write_report(out)}")
    return 0 if holds else 1


def _report(args: argparse.Namespace) -> int:
    from stylesync.metrics.report import write_report

    if not Path(args.folder).is_dir():
        raise ConfigError(f"{args.folder}: not a folder")
    print(write_report(args.folder))
    return 0


def _add_export_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--export-bvh", type=typed.out_file, help="write the character's motion as BVH")
    p.add_argument("--export-mp4", type=typed.out_file, help="write an MP4 of the character (software renderer)")
    p.add_argument("--viewer", default="none", choices=("none", "web", "gui"),
                   help="web: browser viewer (prints its address); gui: PyBullet window mirroring the character. "
                        "A viewer paces the run to the wall clock")
    p.add_argument("--viewer-host", default="127.0.0.1", help="address the web viewer listens on")
    p.add_argument("--viewer-port", type=typed.port, help="web viewer port (default: a free one)")
    p.add_argument("--viewer-hz", type=typed.rate_hz, default=VIEWER_DRAW_HZ, help="viewer drawing rate [Hz]")


def _add_session_args(p: argparse.ArgumentParser, out_default: str, realtime_help: str) -> None:
    """Options shared by the commands that run a session (demo, run)."""
    p.add_argument("--out", type=typed.out_dir, default=out_default, help="output folder")
    p.add_argument("--gui", action="store_true", help="open the PyBullet window")
    p.add_argument("--realtime", action="store_true", help=realtime_help)
    p.add_argument("--no-lipm", action="store_true", help="switch the LIPM time-sync compensation off (Eq. 21-23)")
    p.add_argument("--mirror", action="store_true",
                   help="the operator's mirror image drives the character (his right side its left), as a person "
                        "facing it on a screen expects")
    p.add_argument("--follow-path", action="store_true",
                   help="keep closer still to the operator's path over the ground: the targets pulled onto it at "
                        "every speed of his, not only below the character's gait's top speed; its own steps between "
                        "his make the transition delays longer (docs/status-log.md)")
    p.add_argument("--in-place", action="store_true",
                   help="the character's steps planned to stop the body and its targets anchored on its own feet: "
                        "it stays about where it started, trailing an operator who walks off, and a recording "
                        "starts at rest (docs/status-log.md)")
    p.add_argument("--free-swing", action="store_true",
                   help="a swing foot follows the operator's while both stand balanced on the other foot, lifted "
                        "only with the weight over that ankle (a kick strikes); by default every swing goes to a "
                        "landing placed for balance")
    p.add_argument("--late-contact-steps", action="store_true",
                   help="a swing held for the operator's landing becomes a step of the character's own where that "
                        "landing would not hold its balance (leaps on one foot, spins); the walks' transition delays "
                        "grow (docs/decisions.md)")
    p.add_argument("--pelvis-joint", action="store_true",
                   help="his skeleton's pelvis joint as his pelvis and the character's pelvis at his height (the "
                        "settings before 2026-12-06); by default his pelvis is the midpoint of his hip joints and the "
                        "character's is lowered 7 cm as he goes, for longer steps (docs/status-log.md)")
    p.add_argument("--no-track-rise", action="store_true",
                   help="the pelvis height's law damps every vertical speed, a jump's push included (by default it "
                        "tracks half the operator's rise begun and kept on both feet; docs/status-log.md)")
    p.add_argument("--damp-angular-momentum", action="store_true",
                   help="the whole body's angular momentum about its COM damped at 5 1/s: looping dances and spins "
                        "stand longer, the walks keep to his path less often (docs/decisions.md)")
    p.add_argument("--motion-ahead", action="store_true",
                   help="the motion stage on the last control tick's state, computed a tick ahead in a second process "
                        "(offline runs about 1.1 times as fast; another simulation: docs/decisions.md)")
    p.add_argument("--record", type=typed.out_file, help="session file to write (default: OUT/session.jsonl)")
    p.add_argument("--progress", action="store_true", help="show a progress line (default: when on a terminal)")
    p.add_argument("--continue-after-fall", action="store_true",
                   help="go on to the end after a fall (the fall is recorded; default: a fall ends the run)")
    _add_export_args(p)


def _measure(args: argparse.Namespace) -> int:
    from stylesync.processing.body_parameters import measure_operator

    opened = _open(args, ClockConfig(), None)
    frames = opened.source.poll(float("inf")) if opened.duration_s is not None else []
    if not frames:
        wait = getattr(opened.source, "wait_first_frame", None)
        if wait is not None and wait(10.0):
            frames = opened.source.poll(0.0)
    opened.source.close()
    if not frames:
        raise SourceError(f"{args.source}: no operator frame to measure")
    cloud = None
    if args.point_cloud:
        from stylesync.processing.point_cloud_volume import load_point_cloud

        cloud = load_point_cloud(args.point_cloud)
    table = measure_operator(frames[: max(1, int(len(frames) * 0.1))], args.mass, cloud)
    print(table.as_text())
    return 0


def _add_source_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--source", required=True,
                   help="bvh:PATH, k4a-json:PATH, deepmimic:NAME|PATH, builtin:NAME, vmc://HOST:PORT, webcam:INDEX, "
                        "video:PATH, k4a:DEVICE")
    p.add_argument("--sensor", default="kinect", choices=("kinect", "none"),
                   help="recorded sources: 16 Hz Kinect-like sensor model, or the frames as recorded")
    p.add_argument("--seed", type=typed.seed, default=0)
    p.add_argument("--joint-map", type=typed.in_file, help="BVH: JSON object canonical joint -> BVH joint name")
    p.add_argument("--bvh-scale", type=typed.scale, help="BVH: file units to metres (default: detected)")
    p.add_argument("--bvh-up", help="BVH: up axis x|y|z, optionally signed (default: detected)")


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def _batch(args: argparse.Namespace) -> int:
    import importlib.util

    from stylesync.batch.clips import BatchSettings, find_clips, jobs_for
    from stylesync.batch.runner import print_progress, run_batch

    executor = args.executor or ("ray" if importlib.util.find_spec("ray") else "processes")
    if args.ray_address and executor != "ray":
        raise ConfigError("--ray-address needs the ray executor")
    settings = BatchSettings(seeds=tuple(range(args.seeds)), sensor=args.sensor, duration_s=args.duration,
                             export_bvh=not args.no_bvh, export_mp4=args.mp4, lipm_time_sync=not args.no_lipm)
    jobs = jobs_for(find_clips(args.input), settings)
    out = Path(args.out)
    print(f"batch: {len(jobs)} runs ({len(jobs) // len(settings.seeds)} clips x {len(settings.seeds)} seeds), "
          f"executor {executor}, outputs in {out}", file=sys.stderr, flush=True)
    counts = run_batch(jobs, settings, out, executor, args.workers, args.ray_address, args.max_retries,
                       progress=print_progress)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    print(json.dumps({"runs": counts.total, "done": counts.done, "failed": counts.failed, "retried": counts.retried,
                      "from_before": counts.skipped, "summary": str(out / "batch.md")}))
    return 0


def _inspect(args: argparse.Namespace) -> int:
    """Print what the BVH reader understood of a file; a skeleton that cannot be mapped is an error (exit 2)."""
    from stylesync.sources.bvh import BvhRecording, load_joint_map
    from stylesync.sources.frame import JOINT_INDEX

    jm = load_joint_map(args.joint_map) if args.joint_map else None
    rec = BvhRecording(args.file, joint_map=jm, scale_m=args.bvh_scale, up_axis=args.up_axis)
    perf = rec.performer
    print(f"file: {rec.path}")
    source = ("the frames (the rest pose does not stand; orientations from the joint positions)"
              if rec.orientations_from_positions else "the rest pose")
    print(f"joints in file: {len(rec.joint_names)}; units: 1 file unit = {rec.scale_m:g} m; up axis: {rec.up_axis}; "
          f"stature {rec.stature_m:.2f} m; from {source}")
    print(f"frames: {len(perf.times_s)} at {1.0 / rec.frame_time_s:.1f} Hz, {perf.duration_s:.2f} s"
          + (f" ({rec.bind_frames_skipped} leading bind-pose frames left out)" if rec.bind_frames_skipped else ""))
    print("joint map (canonical <- file joint: how matched):")
    for canon, (name, how) in sorted(rec.matches.items(), key=lambda kv: JOINT_INDEX[kv[0]]):
        print(f"  {canon:15s} <- {name:24s} {how}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The command line's parser: every value typed and range-checked (cli_args.py)."""
    parser = typed.OneLineParser(prog="stylesync", description="Style-preserving humanoid teleoperation")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error (for developers)")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the built-in operator through the whole pipeline, headless")
    demo.add_argument("--clip", default="walk", help="pybullet_data humanoid3d clip, or 'stand'")
    demo.add_argument("--duration", type=typed.duration_s, default=12.0, help="simulated seconds")
    demo.add_argument("--seed", type=typed.seed, default=0)
    demo.add_argument("--turn-rate", type=typed.turn_rate_rad_s, default=0.0,
                      help="the clip's path bent into a turn at this rate after the lead-in [rad/s] (+: to the left)")
    demo.add_argument("--start-ramp", choices=START_RAMPS, default=OperatorConfig().start_ramp,
                      help="a looping clip's start: blended in from a stand (default), or its own poses at a rate "
                           "growing from 0 (no foot slides, no turn but the clip's)")
    _add_session_args(demo, "out/demo", "pace to the wall clock")
    demo.set_defaults(func=_demo)
    run = sub.add_parser("run", help="drive the character from an operator source")
    _add_source_args(run)
    run.add_argument("--duration", type=typed.duration_s, help="simulated seconds (default: the recording's length)")
    run.add_argument("--stream-timeout", type=typed.duration_s, default=SessionConfig().stream_timeout_s,
                     help="live sources: seconds of silence that end the run (shorter ones are held)")
    _add_session_args(run, "out/run", "pace to the wall clock (always for live sources)")
    run.set_defaults(func=_run)
    measure = sub.add_parser("measure", help="print the operator's link table (Sec. 4.2, Table 2)")
    _add_source_args(measure)
    measure.add_argument("--mass", type=typed.mass_kg, default=75.8, help="operator's total mass [kg]")
    measure.add_argument("--point-cloud", type=typed.in_file,
                         help="body point cloud (.ply or .npy, metres, world frame)")
    measure.set_defaults(func=_measure)
    experiment = sub.add_parser("experiment", help="re-run one of the paper's experiments (Sec. 7.4)")
    experiment.add_argument("name", choices=("sync", "push", "styles", "kick", "squat-jump", "tune"))
    experiment.add_argument("--duration", type=typed.duration_s, default=12.0)
    experiment.add_argument("--seed", type=typed.seed, default=0)
    experiment.add_argument("--out", type=typed.out_dir, default="out/experiments")
    experiment.set_defaults(func=_experiment)
    report = sub.add_parser("report", help="write report.html for a run, bench or experiment folder")
    report.add_argument("folder", type=typed.in_dir)
    report.set_defaults(func=_report)
    bench = sub.add_parser("bench", help="stylesync vs plain PD vs no model-based compensation over the clip suite")
    bench.add_argument("--duration", type=typed.duration_s, default=10.0, help="simulated seconds per clip")
    bench.add_argument("--seed", type=typed.seed, default=0,
                       help="sensor seed (the dev suite's first: --seed 8 --seeds 8 runs seeds 8-15)")
    bench.add_argument("--out", type=typed.out_dir, default="out/bench", help="output folder (bench.md, bench.json)")
    bench.add_argument("--shared", type=typed.in_dir,
                       help="folder holding mocap/cmu (default: ../shared beside the checkout)")
    bench.add_argument("--suite", choices=("bench", "dev"), default="bench",
                       help="bench: the humanoid3d clips and CMU BVH against two baselines; dev: every shared clip "
                            "per category, several seeds, stylesync and the plain PD tracker (dev_suite.md/json)")
    bench.add_argument("--seeds", type=typed.integer(1, 1000), default=2,
                       help="dev suite: sensor seeds SEED .. SEED+N-1")
    bench.add_argument("--only", help="dev suite: comma-separated categories (default: all)")
    bench.add_argument("--clips", action="append", metavar="INPUT",
                       help="dev suite: also your own clips, as stylesync batch finds them (a folder searched "
                            "recursively, a glob, a list file or a clip file; repeatable); a clip's category is the "
                            "nearest folder named after one (e.g. mine/walk/a.bvh), otherwise 'other'")
    bench.add_argument("--clips-only", action="store_true",
                       help="dev suite: only the clips of --clips (not the humanoid3d and shared clips)")
    bench.add_argument("--mirror", action="store_true",
                       help="dev suite: every clip's mirror image (left and right swapped), a second sample of what "
                            "users bring")
    bench.add_argument("--sensor-noise", type=typed.noise_factor, default=1.0,
                       help="dev suite: the sensor model's joint position and orientation noise times this (1: "
                            "Kinect-like, 5 mm and 0.02 rad; a webcam's pose model is noisier)")
    bench.add_argument("--follow-path", action="store_true",
                       help="dev suite: also the controller with --follow-path's settings, in the same run (the "
                            "'follow-path' rows, paired with stylesync's)")
    bench.add_argument("--in-place", action="store_true",
                       help="dev suite: also the controller with --in-place's settings, in the same run (the "
                            "'in-place' rows, paired with stylesync's)")
    bench.add_argument("--pelvis-joint", action="store_true",
                       help="dev suite: also the controller with --pelvis-joint's settings, in the same run (the "
                            "'pelvis-joint' rows, paired with stylesync's)")
    bench.add_argument("--workers", type=typed.integer(1, 256), default=2,
                       help="runs in parallel (with --executor processes or ray, and for the dev suite)")
    bench.add_argument("--executor", choices=("processes", "ray", "inline"),
                       help="where the runs go (stylesync batch's executors); default: processes for the dev suite, "
                            "inline for the bench (its realtime factors are then measured alone)")
    bench.set_defaults(func=_bench)
    batch = sub.add_parser("batch", help="run every clip of a folder, glob or list through the pipeline (Ray)")
    batch.add_argument("input", help="folder (recursive), glob pattern, list file (.list/.lst) or clip file")
    batch.add_argument("--out", type=typed.out_dir, default="out/batch", help="output folder")
    batch.add_argument("--seeds", type=typed.integer(1, 1000), default=1, help="sensor seeds 0 .. N-1 per clip")
    batch.add_argument("--sensor", default="kinect", choices=("kinect", "none"),
                       help="16 Hz Kinect-like sensor model, or the frames as recorded")
    batch.add_argument("--duration", type=typed.duration_s, help="cap on each run's simulated seconds")
    batch.add_argument("--no-lipm", action="store_true", help="switch the LIPM time-sync compensation off")
    batch.add_argument("--no-bvh", action="store_true", help="do not export each run's motion as BVH")
    batch.add_argument("--mp4", action="store_true", help="also render each run to MP4 (slow)")
    batch.add_argument("--executor", choices=("ray", "processes", "inline"),
                       help="ray (default when installed), processes (a local pool) or inline")
    batch.add_argument("--workers", type=typed.integer(1, 4096), help="parallel runs (default: one per core)")
    batch.add_argument("--ray-address", help="join a Ray cluster (HOST:PORT or 'auto') instead of a local Ray")
    batch.add_argument("--max-retries", type=typed.integer(0, 100), default=2,
                       help="times a job whose worker or node died is submitted again")
    batch.set_defaults(func=_batch)
    inspect = sub.add_parser("inspect", help="show how a BVH file is understood: joint map, units, axes, frames")
    inspect.add_argument("file", type=typed.in_file, help="BVH file")
    inspect.add_argument("--joint-map", type=typed.in_file,
                         help="JSON object canonical joint -> BVH joint name, overriding the matching")
    inspect.add_argument("--bvh-scale", type=typed.scale, help="file units to metres (default: found from the stature)")
    inspect.add_argument("--up-axis", help="the file's up axis, e.g. y or -z (default: found from the rest pose)")
    inspect.set_defaults(func=_inspect)
    replay = sub.add_parser("replay", help="replay a session file (no re-simulation) into BVH and/or MP4")
    replay.add_argument("file", help="session file (.jsonl) written by run or demo")
    replay.add_argument("--speed", type=typed.speed, default=1.0, help="viewer playback speed (1 = real time)")
    _add_export_args(replay)
    replay.set_defaults(func=_replay)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    if threading.current_thread() is threading.main_thread():
        # A termination request (kill, a supervisor stopping the run) ends the run as Ctrl-C does: the session
        # stops, the session file is closed and the viewer process shut down. SIGINT (Ctrl-C) ends it too whatever
        # its parent left: a shell without job control starts a background command with SIGINT ignored, every
        # process below it inherits that, and Python then leaves it ignored (a realtime demo started under such a
        # command went on pacing its 60 s after a SIGINT).
        signal.signal(signal.SIGTERM, _interrupt)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    # Exit codes: 2 for input the parser or a source refuses (options, files, streams, settings); 1 for a failure
    # while running (the simulation, the system refusing a file); 130 when interrupted. --debug keeps tracebacks.
    try:
        return int(args.func(args))
    except (SourceError, ConfigError) as exc:
        if args.debug:
            raise
        print(f"stylesync: error: {exc}", file=sys.stderr)
        return 2
    except StylesyncError as exc:
        if args.debug:
            raise
        print(f"stylesync: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("stylesync: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:  # a folder or file the system refuses (permissions, a full disk, a read-only system)
        if args.debug:
            raise
        where = f": {exc.filename}" if exc.filename else ""
        print(f"stylesync: error: {exc.strerror or exc}{where}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())

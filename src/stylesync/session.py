"""The clocks and the loop that wires the stages (Fig. 2): source -> processing -> motion -> control -> physics.

Three clocks (Sec. 7.1): mocap frames arrive at their own rate (16 Hz), the control tick runs at 133 Hz, the
physics at 600 Hz. Simulated time is the master clock: a control tick runs on the first physics step at or after
its due time, so the same input, configuration and seed give the same simulation whether the loop is paced to the
wall clock (interactive) or runs as fast as possible (offline).
"""

from __future__ import annotations

import logging
import queue
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from stylesync import rotations as rot
from stylesync.config import SessionConfig
from stylesync.control.controller import BalanceController, ControllerBase
from stylesync.control.pid import joint_error
from stylesync.control.whole_body import WholeBodyController
from stylesync.errors import SourceError
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    CHARACTER_LINKS,
    LEG_LINKS,
    LINK_NAMES,
    OPERATOR_JOINTS,
    STANDING_ROOT_HEIGHT_M,
)
from stylesync.model.character_model import CharacterModel
from stylesync.model.sole import sole_corner_points, sole_points_xy
from stylesync.model.state import CharacterState
from stylesync.motion.bounds import BoundsMonitor
from stylesync.motion.initial_state import InitialState, initial_state, standing_start_shift, start_velocity_share
from stylesync.motion.operator_analysis import analyse_operator
from stylesync.motion.pose_optimization import MotionOptimizer
from stylesync.motion.reference import MotionReading
from stylesync.motion.stance_fsm import Stance
from stylesync.motion.style_features import ROW_NAMES as _FEATURES
from stylesync.motion.style_features import style_rows
from stylesync.motion_ahead import MotionAhead, MotionInline
from stylesync.prefetch import OperatorInline, OperatorPrefetch
from stylesync.processing.body_parameters import paired_operator_joints
from stylesync.processing.joint_map import tracked_arrays
from stylesync.processing.operator_processing import OperatorProcessing, OperatorSample
from stylesync.sim.backend import PhysicsBackend
from stylesync.sim.factory import make_backend
from stylesync.sources.base import OperatorSource
from stylesync.sources.frame import OperatorFrame
from stylesync.sources.mirror import MirroredSource

log = logging.getLogger("stylesync.session")
FALL_ROOT_HEIGHT_M = 0.5  # a fall: pelvis below this height, or a non-foot link on the ground
# A diverged motion, counted as a fall: a link faster than a human limb ever moves (a trained kick's foot reaches
# about 15-20 m/s), or the pelvis higher than a jump can lift it (0.88 m standing).
DIVERGED_LINK_SPEED_MPS = 25.0
DIVERGED_ROOT_HEIGHT_M = 2.5
# How a fall reason begins, per kind of fall (Session._fall_reason): the pelvis low, a link other than a foot on the
# ground, the motion diverged. The development suite counts falls by these (metrics/dev_suite.fall_endings).
FALL_REASON_PREFIXES = ("pelvis at", "a link other than a foot", "the motion diverged")
FIRST_FRAME_TIMEOUT_S = 10.0
# A standing start (Session._starts_standing): both ankles within this of one height [m], and the feet's shift
# found again this many times (the legs' own mass moves the COM a little with them)
STANDING_START_ANKLE_GAP_M = 0.03
STANDING_START_ITERATIONS = 3


def _all_tracked(frame: OperatorFrame) -> bool:
    """Whether every joint the processing stage reads is tracked in ``frame``."""
    _, _, cq, cp = tracked_arrays(frame)
    return bool(np.all(cq > 0) and np.all(cp > 0))
_LINK = {n: i for i, n in enumerate(LINK_NAMES)}
# Hip, knee and ankle links of the left and the right leg, (2, 3).
_LEG_LINKS = np.array([LEG_LINKS[s] for s in ("left", "right")])
STANCE_CODE = {Stance.LS: 0, Stance.DS: 1, Stance.RS: 2}


@dataclass
class TickLog:
    """Per-control-tick record of a run (lists of equal length)."""

    columns: dict[str, list] = field(default_factory=dict)

    def add(self, **values) -> None:
        for k, v in values.items():
            self.columns.setdefault(k, []).append(v)

    def array(self, key: str) -> np.ndarray:
        return np.asarray(self.columns.get(key, []), dtype=float)

    def drop_partial_tick(self) -> int:
        """Cut every column to the shortest one's length: a tick whose record an interrupt (Ctrl-C) cut short
        between two columns is dropped whole. Returns the number of ticks kept."""
        n = min((len(v) for v in self.columns.values()), default=0)
        for values in self.columns.values():
            del values[n:]
        return n


@dataclass
class SessionResult:
    log: TickLog
    fell: bool
    fall_time_s: float | None
    fall_reason: str
    sim_duration_s: float
    wall_duration_s: float  # of the loop, without pauses and without rendering the strip (render_every_s)
    physics_steps: int
    rejected_frames: int
    dropped_joint_values: int
    bound_counts: dict[str, int]
    stage_ms: dict[str, list[float]]
    input_latency_ms: list[float] = field(default_factory=list)  # live frames: arrival -> first control tick using it
    operator_prefetched: bool = False  # the operator side ran ahead in a second process (prefetch.py)
    end_reason: str = ""  # why the run ended before its duration without a fall ("" : it did not)
    rejections: dict[str, int] = field(default_factory=dict)  # a live source's rejected packets/frames by reason


@dataclass
class _RunState:
    """What one run accumulates: the tick log, stage timings, the fall, the wall clock's origin."""

    render_every_s: float | None
    log: TickLog = field(default_factory=TickLog)
    stage_ms: dict[str, list[float]] = field(default_factory=lambda: {
        "processing": [], "motion": [], "control_update": [], "torques": [], "physics": []})
    latency_ms: list[float] = field(default_factory=list)
    fall_time: float | None = None
    fall_reason: str = ""
    wall0: float = 0.0
    last_frame_sim_s: float = 0.0
    end_reason: str = ""
    next_render_s: float = 0.0


def control_tick_steps(n_steps: int, physics_dt_s: float, control_dt_s: float) -> list[int]:
    """The physics steps a control tick runs on: the first step at or after each control period's due time."""
    steps, next_control = [], 0.0
    for step in range(n_steps):
        if step * physics_dt_s + 1e-12 >= next_control:
            next_control += control_dt_s
            steps.append(step)
    return steps


class Session:
    def __init__(self, config: SessionConfig, source: OperatorSource, backend: PhysicsBackend | None = None,
                 on_tick: Callable[[CharacterState, object], None] | None = None):
        self.cfg = config
        self.source = MirroredSource(source) if config.operator.mirror else source
        self._owns_backend = backend is None
        self.backend = backend or make_backend(config.world, config.clocks.physics_hz, gui=config.gui)
        self.mass = self.backend.mass_properties()
        self.processing = OperatorProcessing(config.clocks, config.filters)
        self.bounds = BoundsMonitor()
        self.motion = MotionOptimizer(config.motion, config.clocks.control_hz, self.bounds,
                                      config.world.gravity_mps2)
        self.model = CharacterModel(self.backend.body_description(), config.world.gravity_mps2)
        self.controller: ControllerBase
        if config.control.balance == "whole_body":
            self.controller = WholeBodyController(
                config.control, self.model, self.mass, config.world.gravity_mps2, 1.0 / config.clocks.physics_hz,
                1.0 / config.clocks.control_hz, self.bounds, config.world.friction)
        else:
            self.controller = BalanceController(
                config.control, self.model, self.mass, config.world.gravity_mps2, 1.0 / config.clocks.physics_hz,
                1.0 / config.clocks.control_hz, self.bounds, config.world.friction)
        self.on_tick = on_tick
        self.renders: list[tuple[float, np.ndarray]] = []
        self.last_sample: OperatorSample | None = None  # newest processed operator sample (recorders, viewers)
        self.last_torques: np.ndarray | None = None  # (n_joints, 3) torques of the last physics step [N·m]
        self.last_com_world: np.ndarray | None = None  # character COM at the last control tick [m]
        # The motion stage's reading of the operator at the last control tick (his stance, style features, scale)
        self.reading: MotionReading | None = None
        # Interactive use (viewers): callables run in the loop's thread at the next control tick, a pause flag
        # honoured there, and whether a fall ends the run (it is recorded either way).
        self.commands: queue.SimpleQueue[Callable[[Session], None]] = queue.SimpleQueue()
        self.paused = False
        self.stop_on_fall = True
        # An offline run of a recorded operator computes the operator side ahead in a second process
        # (prefetch.py; the same results). False keeps it in this process.
        self.prefetch_operator = True
        # Ctrl-C (or SIGTERM, turned into it by the command line) ends the run as its duration would, with
        # end_reason "interrupted", instead of propagating (the command line then writes the outputs and exits 130)
        self.finish_on_interrupt = False
        self.closed = False
        self.fell = False  # the run has recorded a fall (viewers show it)

    def release_engine(self) -> None:
        """Disconnect the physics engine this session made (each holds tens of MB in the engine): after a run
        and whatever is read from its state. A process that runs many sessions (bench, batch) calls it."""
        if self._owns_backend:
            self.backend.close()
            self._owns_backend = False

    def reset_character(self) -> None:
        """Stand the character up again where the operator now stands (an interactive reset; it is not a force
        on the character but a new initial state, like the start of a run)."""
        sample = self.last_sample
        if sample is None:
            return
        self._stand_at(sample.pos["PELVIS"], sample.quat["PELVIS"])
        self.controller.reset()

    def _stand_at(self, pelvis_world: np.ndarray, pelvis_quat_wxyz: np.ndarray) -> None:
        """Character standing at the operator's pelvis position (horizontally) and heading."""
        yaw = rot.heading_from_quat(pelvis_quat_wxyz)
        self.backend.reset(np.array([pelvis_world[0], pelvis_world[1], STANDING_ROOT_HEIGHT_M + 0.003]),
                           rot.quat_from_yaw(yaw))

    def _service_commands(self) -> None:
        while True:
            try:
                command = self.commands.get_nowait()
            except queue.Empty:
                return
            command(self)

    def _place_character(self) -> None:
        """Stand the character where the operator stands (scaled), facing the operator's heading, once a frame with
        every tracked joint has arrived (the processing stage cannot start from one with lost joints)."""
        wait = getattr(self.source, "wait_first_frame", None)
        if wait is not None and not wait(FIRST_FRAME_TIMEOUT_S):
            raise SourceError(f"no operator frame arrived within {FIRST_FRAME_TIMEOUT_S:.0f} s")
        frames = self._first_complete_frames(live=wait is not None)
        if getattr(self.source, "starts_in_motion", False) and len(frames) > 1:
            if self._start_in_motion(frames[-2], frames[-1]):  # False when either frame lost joints
                return
        f0 = next(f for f in reversed(frames) if _all_tracked(f))
        self._stand_at(f0.pos("PELVIS"), f0.quat("PELVIS"))

    def _first_complete_frames(self, live: bool) -> list[OperatorFrame]:
        """The frames up to the first with every tracked joint, pushed into the processing stage: a live source's as
        they arrive (at most FIRST_FRAME_TIMEOUT_S), a recording's from its start onwards (its first
        FIRST_FRAME_TIMEOUT_S); one clear error when there is none."""
        frames = self.source.poll(0.0)
        for f in frames:
            self.processing.push(f)
        t_s, deadline = 0.0, time.perf_counter() + FIRST_FRAME_TIMEOUT_S
        while not self.processing.ready:
            if live:
                if time.perf_counter() > deadline:
                    raise SourceError(f"no operator frame with every joint tracked arrived within "
                                      f"{FIRST_FRAME_TIMEOUT_S:.0f} s ({len(frames)} frames had lost joints)")
                time.sleep(0.005)
                new = self.source.poll(0.0)
            else:
                t_s += 1.0 / self.cfg.clocks.mocap_hz
                if t_s > FIRST_FRAME_TIMEOUT_S:
                    raise SourceError(f"the operator source delivered no frame with every joint tracked in its first "
                                      f"{FIRST_FRAME_TIMEOUT_S:.0f} s ({len(frames)} frames, with lost joints)")
                new = self.source.poll(t_s)
            for f in new:
                self.processing.push(f)
            frames += new
        if t_s > 0.0:
            log.info("the operator's first frame with every joint tracked came at %.2f s (%d frames before it)",
                     t_s, len(frames) - 1)
        return frames

    def _start_in_motion(self, f0: OperatorFrame, f1: OperatorFrame) -> bool:
        """The character in the operator's pose of frame ``f0`` (the reference-state initialisation of
        motion/initial_state.py), its lower foot on the ground; with ``start_with_clip_velocity``, moving with the
        velocities from ``f0`` to ``f1``. False when a frame lacks joints. A source that starts in motion delivers
        both at t = 0 (sources/registry.py)."""
        samples = []
        for f in (f0, f1):
            processing = OperatorProcessing(self.cfg.clocks, self.cfg.filters)
            processing.push(f)
            if not processing.ready:
                return False
            samples.append(processing.step(f.timestamp_s))
        s0, s1 = samples
        a0, a1 = analyse_operator(s0), analyse_operator(s1)
        motion = self.cfg.motion
        init = initial_state(s0, a0, s1, a1, motion.pelvis_from_hip_joints, motion.pelvis_min_height_m)
        share = (start_velocity_share(init.root_lin_vel_world, self.cfg.operator.start_speed_max_mps)
                 if self.cfg.operator.start_with_clip_velocity else 0.0)
        state = self._reset_on_ground(init)
        standing = self._starts_standing(state, share * init.root_lin_vel_world)
        if standing and motion.standing_start_at_rest:
            share = 0.0
        shift, sole_share = np.zeros(3), motion.standing_start_sole_share
        if standing and sole_share is not None:
            for _ in range(STANDING_START_ITERATIONS):
                more = self._standing_start_shift(state, share * init.root_lin_vel_world, sole_share)
                if more is None:
                    break
                shift += more
                init = initial_state(s0, a0, s1, a1, motion.pelvis_from_hip_joints, motion.pelvis_min_height_m, shift)
                state = self._reset_on_ground(init)
        if shift.any():
            log.info("a standing start: the character's feet set %.3f m further under its capture point",
                     float(np.hypot(shift[0], shift[1])))
        if self.cfg.operator.start_with_clip_velocity:
            self.backend.set_velocities(share * init.root_lin_vel_world, share * init.root_ang_vel_world,
                                        share * init.joint_vel)
            self.processing.prime_rates(f0, f1)
            com_vel_h = (s1.com_world - s0.com_world) / (s1.time_s - s0.time_s)
            self.motion.prime_rates(com_vel_h, share * init.root_lin_vel_world)
        return True

    def _reset_on_ground(self, init: InitialState) -> CharacterState:
        """The character reset to ``init`` at rest, its lower ankle at its standing height over the ground."""
        self.backend.reset(init.root_pos_world, init.root_quat_wxyz, init.joint_pos)
        ankle_z = self.backend.read_state(0.0).link_origin_world[_LEG_LINKS[:, 2], 2]
        root = init.root_pos_world + np.array([0.0, 0.0, ANKLE_HEIGHT_M + 0.002 - float(ankle_z.min())])
        self.backend.reset(root, init.root_quat_wxyz, init.joint_pos)
        return self.backend.read_state(0.0)

    def _starts_standing(self, state: CharacterState, root_vel_world: np.ndarray) -> bool:
        """Whether the character at rest in ``state``, about to start with the root velocity ``root_vel_world``
        [m/s], starts standing: both ankles on the ground and that velocity below
        ``MotionConfig.gait_min_way_speed_mps`` over the ground (a clip started mid-stride is not)."""
        motion = self.cfg.motion
        standing_mps = motion.gait_min_way_speed_mps if motion.gait_min_way_speed_mps is not None else 0.0
        ankles_z = state.link_origin_world[_LEG_LINKS[:, 2], 2]
        return (float(np.hypot(root_vel_world[0], root_vel_world[1])) < standing_mps
                and float(np.ptp(ankles_z)) <= STANDING_START_ANKLE_GAP_M)

    def _standing_start_shift(self, state: CharacterState, com_vel_world: np.ndarray,
                              sole_share: float) -> np.ndarray | None:
        """motion/initial_state.standing_start_shift for the character at rest in ``state``, standing
        (:meth:`_starts_standing`), about to start with the COM velocity ``com_vel_world`` [m/s] (its root's, near
        enough at a standing start), its soles shrunk to ``sole_share`` (MotionConfig.standing_start_sole_share)."""
        corners = sole_corner_points(sole_share)
        soles = [sole_points_xy(state.link_origin_world[ankle], state.link_quat_wxyz[ankle], corners)
                 for ankle in _LEG_LINKS[:, 2]]
        return standing_start_shift(self.mass.com(state), com_vel_world, self.cfg.world.gravity_mps2, soles)

    def run(self, progress: Callable[[float, float], None] | None = None,
            render_every_s: float | None = None) -> SessionResult:
        """Run the session for ``duration_s`` of simulated time (or until a fall, or ``close``)."""
        cfg = self.cfg
        dt = 1.0 / cfg.clocks.physics_hz
        n_steps = int(round(cfg.duration_s * cfg.clocks.physics_hz))
        self._place_character()
        run = _RunState(render_every_s)
        tick_steps = control_tick_steps(n_steps, dt, 1.0 / cfg.clocks.control_hz)
        is_tick = [False] * n_steps  # Python bools: read at every physics step
        for k in tick_steps:
            is_tick[k] = True
        operator: OperatorInline | OperatorPrefetch = OperatorInline(self.source, self.processing)
        stage: MotionInline | MotionAhead = MotionInline(self.motion, self.mass, cfg.motion_ahead)
        if self.prefetch_operator and OperatorPrefetch.usable(self.source, cfg.realtime, cfg.gui):
            if cfg.motion_ahead:  # forked first: the operator side's worker then holds no end of its pipe
                stage = MotionAhead(self.motion, self.mass, self.bounds)
            operator = OperatorPrefetch(self.source, self.processing, [k * dt for k in tick_steps])
        self.fell = False
        run.wall0 = time.perf_counter()
        step = 0
        try:
            for step in range(n_steps):
                t = step * dt
                if is_tick[step]:
                    self._wait_while_paused(run)
                    state = self._control_tick(t, operator, stage, run)
                    if self._detect_fall(state, t, run) or self.closed or run.end_reason:
                        break
                    self._render_if_due(state, t, run)
                    if progress is not None:
                        progress(t, time.perf_counter() - run.wall0)
                self._physics_step(run)
                if cfg.realtime:
                    self._pace(t + dt, run)
        except KeyboardInterrupt:
            if not self.finish_on_interrupt:
                raise
            run.end_reason = "interrupted"  # the run ends here and its outputs are written
            run.log.drop_partial_tick()  # the interrupt may have come while the tick was being recorded
            log.warning("interrupted at t=%.2f s: the run ends there", step * dt)
        finally:
            operator.close()
            stage.close()
        _add_after_run_columns(run.log)
        bounds_line = self.bounds.summary(cfg.clocks.control_hz)
        if bounds_line is not None:
            log.warning(bounds_line)
        wall = time.perf_counter() - run.wall0
        sim_t = (step + 1) * dt if not (self.fell and self.stop_on_fall) else float(run.fall_time or 0.0)
        return SessionResult(run.log, self.fell, run.fall_time, run.fall_reason, sim_t, wall, step + 1,
                             operator.rejected_frames, operator.dropped_joint_values,
                             dict(self.bounds.counts), run.stage_ms, run.latency_ms,
                             isinstance(operator, OperatorPrefetch), run.end_reason,
                             dict(getattr(self.source, "rejections", {})))

    # ---- the parts of a run ----------------------------------------------------------------------------------
    def _wait_while_paused(self, run: _RunState) -> None:
        """Commands from viewers, and a pause: neither simulated time nor wall time of the run."""
        self._service_commands()
        if self.paused:
            p0 = time.perf_counter()
            while self.paused and not self.closed:
                time.sleep(0.02)
                self._service_commands()
            run.wall0 += time.perf_counter() - p0

    def _control_tick(self, t: float, operator: OperatorInline | OperatorPrefetch, stage: MotionInline | MotionAhead,
                      run: _RunState) -> CharacterState:
        """Operator side, motion optimisation and the controller's update for the control tick at ``t``. The motion
        stage reads the operator's sample of this tick and the character's state of this tick, or with
        ``SessionConfig.motion_ahead`` of the last (motion_ahead.py)."""
        c0 = time.perf_counter()
        frames = operator.poll(t)
        for f in frames:
            if "arrival_wall_s" in f.extras:
                run.latency_ms.append((c0 - f.extras["arrival_wall_s"]) * 1e3)
        self._watch_stream(bool(frames), t, run)
        sample, analysis = operator.tick(t)
        self.last_sample = sample
        c1 = time.perf_counter()
        state = self.backend.read_state(t)
        if isinstance(stage, MotionAhead):
            assert isinstance(operator, OperatorPrefetch)  # (the motion stage runs ahead only beside it)
            ref, self.reading = stage.reference(operator.last_row, operator.next_row(), state)
        else:
            ref, self.reading = stage.reference(sample, analysis, state)
        c2 = time.perf_counter()
        self.controller.update(state, ref)
        c3 = time.perf_counter()
        run.stage_ms["processing"].append((c1 - c0) * 1e3)
        run.stage_ms["motion"].append((c2 - c1) * 1e3)
        run.stage_ms["control_update"].append((c3 - c2) * 1e3)
        self._log(run.log, t, sample, state, ref, (c3 - c0) * 1e3)
        if self.on_tick is not None:
            self.on_tick(state, ref)
        return state

    def _watch_stream(self, got_frames: bool, t: float, run: _RunState) -> None:
        """Watchdog of a live stream. While it is silent the operator side holds his last sample (the character
        keeps balancing in his last pose) and the run goes on when frames come back; silent for longer than
        ``SessionConfig.stream_timeout_s``, the run ends there, as a run that has reached its duration (its
        outputs are written), with the reason in ``end_reason``."""
        if got_frames:
            run.last_frame_sim_s = t
        elif t - run.last_frame_sim_s > self.cfg.stream_timeout_s and self._source_is_live():
            run.end_reason = f"operator stream silent for more than {self.cfg.stream_timeout_s:g} s"
            log.warning("%s: run ended at t=%.2f s", run.end_reason, t)

    def _detect_fall(self, state: CharacterState, t: float, run: _RunState) -> bool:
        """Record the first fall; whether the run ends here."""
        reason = self._fall_reason(state)
        if reason and not self.fell:
            self.fell, run.fall_time, run.fall_reason = True, t, reason
            log.warning("character fell at t=%.2f s (%s)", t, reason)
        return self.fell and self.stop_on_fall

    def _render_if_due(self, state: CharacterState, t: float, run: _RunState) -> None:
        """The rendered strip: an output of the run, not part of the pipeline's time."""
        if run.render_every_s is None or t < run.next_render_s or not hasattr(self.backend, "render_rgb"):
            return
        run.next_render_s += run.render_every_s
        r0 = time.perf_counter()
        com = self.mass.com(state)
        self.renders.append((t, self.backend.render_rgb([com[0], com[1], 0.8])))  # type: ignore[attr-defined]
        run.wall0 += time.perf_counter() - r0

    def _physics_step(self, run: _RunState) -> None:
        p0 = time.perf_counter()
        fb = self.backend.read_joint_feedback() if self.controller.needs_joint_feedback else None
        torques = self.controller.torques(fb)
        self.last_torques = torques.values
        self.backend.apply_torques(torques)
        p1 = time.perf_counter()
        self.backend.step()
        p2 = time.perf_counter()
        run.stage_ms["torques"].append((p1 - p0) * 1e3)
        run.stage_ms["physics"].append((p2 - p1) * 1e3)

    @staticmethod
    def _pace(t_next: float, run: _RunState) -> None:
        """Paced to the wall clock: wait until simulated time ``t_next`` is due."""
        lag = t_next - (time.perf_counter() - run.wall0)
        if lag > 0:
            time.sleep(lag)

    def _source_is_live(self) -> bool:
        return bool(getattr(self.source, "live", False))

    @staticmethod
    def _fall_reason(state: CharacterState) -> str:
        if state.root_pos_world[2] < FALL_ROOT_HEIGHT_M:
            return f"{FALL_REASON_PREFIXES[0]} {state.root_pos_world[2]:.2f} m < {FALL_ROOT_HEIGHT_M} m"
        if state.non_foot_ground_contact:
            return f"{FALL_REASON_PREFIXES[1]} touched the ground"
        # A run-away controller (or simulation) is a failure too, even while the body is in the air.
        v = state.link_com_vel_world
        speed_sq = float((v * v).sum(axis=1).max())  # the fastest link's squared speed [m²/s²]
        if speed_sq > DIVERGED_LINK_SPEED_MPS ** 2 or state.root_pos_world[2] > DIVERGED_ROOT_HEIGHT_M:
            speed = speed_sq ** 0.5
            return (f"{FALL_REASON_PREFIXES[2]} (a link at {speed:.0f} m/s, pelvis at {state.root_pos_world[2]:.1f} m; "
                    f"limits {DIVERGED_LINK_SPEED_MPS:.0f} m/s, {DIVERGED_ROOT_HEIGHT_M:.1f} m)")
        return ""

    def _log(self, lg: TickLog, t: float, sample, state: CharacterState, ref, tick_ms: float) -> None:
        com = self.mass.com(state)
        self.last_com_world = com
        # Vectors are recorded whole and split into their x, y, z columns after the run (_add_after_run_columns):
        # the tick pays for one append per vector. The arrays recorded are new at every tick, never changed later.
        reading = self.reading
        assert reading is not None  # the motion stage has run this tick
        lg.add(
            t=t, tick_ms=tick_ms,
            op_state=STANCE_CODE[reading.operator_stance], char_state=STANCE_CODE[ref.character_stance],
            held=float(reading.held), scale=reading.scale,
            _v_com=com, _v_com_d=ref.com_world, _v_op_com=sample.com_world,
            _v_op_al=sample.pos["ANKLE_LEFT"], _v_op_ar=sample.pos["ANKLE_RIGHT"],
            _v_al=state.link_origin_world[_LINK["left_ankle"]], _v_ar=state.link_origin_world[_LINK["right_ankle"]],
            root_z=float(state.root_pos_world[2]),
            contact_l=state.foot_contact_force_n["left_ankle"], contact_r=state.foot_contact_force_n["right_ankle"],
            ch_joints=state.link_origin_world[CHARACTER_LINKS],
            _op_pos=sample.pos,
            _v_lipm=self.controller.telemetry.lipm_force_n,
            _op_features=reading.operator_features,
            # The joint error and the character's style features are computed from these after the run
            # (_add_after_run_columns). The arrays are the state's and the reference's own, new at every tick.
            _q=state.joint_pos, _q_ref=ref.joint_pos,
            _ch_legs=state.link_origin_world[_LEG_LINKS], _ch_leg_quats=state.link_quat_wxyz[_LEG_LINKS[:, 1:]],
            _ch_root_quat=state.root_quat_wxyz,
        )


# Vector columns recorded whole at each tick: (recorded name, column prefix, axes split off).
_VECTOR_COLUMNS = (("_v_com", "com", "xyz"), ("_v_com_d", "com_d", "xyz"), ("_v_op_com", "op_com", "xyz"),
                   ("_v_op_al", "op_al", "xyz"), ("_v_op_ar", "op_ar", "xyz"), ("_v_al", "al", "xyz"),
                   ("_v_ar", "ar", "xyz"), ("_v_lipm", "lipm_f", "xy"))


def _add_after_run_columns(lg: TickLog) -> None:
    """Columns derived from what each tick recorded, in one batched computation after the run instead of one per
    control tick: ``joint_err_deg`` (mean over the joints of the angle between the character's joint and the
    reference's) and the character's style features (Sec. 5.2), ``ch_<feature>``."""
    ch_com = lg.columns.get("_v_com", [])  # the character's COM, for its style features below
    for key, prefix, axes in _VECTOR_COLUMNS:
        values = lg.columns.pop(key, [])
        if values:
            arr = np.asarray(values, dtype=float)
            for k, axis in enumerate(axes):
                lg.columns[f"{prefix}_{axis}"] = arr[:, k].tolist()
    op_pos = lg.columns.pop("_op_pos", [])
    if op_pos:
        lg.columns["op_joints"] = [paired_operator_joints(pos, OPERATOR_JOINTS) for pos in op_pos]
    features = lg.columns.pop("_op_features", [])
    if features:
        arr = np.asarray([f.as_row() for f in features], dtype=float)
        for k, name in enumerate(_FEATURES):
            lg.columns[f"op_{name}"] = arr[:, k].tolist()
    raw = {k: lg.columns.pop(k, []) for k in ("_q", "_q_ref", "_ch_legs", "_ch_leg_quats", "_ch_root_quat")}
    if not ch_com:
        return
    err = joint_error(np.asarray(raw["_q"]), np.asarray(raw["_q_ref"]))  # (n, n_joints, 3)
    lg.columns["joint_err_deg"] = np.degrees(np.linalg.norm(err, axis=2)).mean(axis=1).tolist()
    legs, quats = np.asarray(raw["_ch_legs"]), np.asarray(raw["_ch_leg_quats"])  # (n, 2, 3, 3), (n, 2, 2, 4)
    rows = style_rows(legs[:, :, 0], legs[:, :, 1], legs[:, :, 2], quats[:, :, 0], quats[:, :, 1],
                      np.asarray(ch_com), np.asarray(raw["_ch_root_quat"]))
    for k, name in enumerate(_FEATURES):
        lg.columns[f"ch_{name}"] = rows[:, k].tolist()


def run_and_release(config: SessionConfig, source: OperatorSource) -> SessionResult:
    """One session of ``config`` on ``source`` run to its end, the source closed and the engine released however
    it ends (processes that run many sessions: bench, the development suite)."""
    try:
        session = Session(config, source)
    except BaseException:
        source.close()
        raise
    try:
        return session.run()
    finally:
        source.close()
        session.release_engine()

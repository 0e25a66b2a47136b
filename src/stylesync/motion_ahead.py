"""The motion stage a control tick ahead of the controller, in a second process (offline runs).

The pipeline's stages run in a chain at every control tick: the motion optimisation reads the operator's sample and
the character's state and hands its reference to the controller, which turns it into torques for the physics steps
up to the next tick. With ``SessionConfig.motion_ahead`` the motion stage reads the character's state of the last
control tick instead (at the first, the first tick's own), 7.5 ms old at 133 Hz, as a state estimator a tick behind
would give it; the operator's sample is the tick's own. Then the simulation is the same whichever process computes
it (session.py):

- in line (``MotionInline``): the motion stage runs in this process before the controller's update;
- ahead (``MotionAhead``): a forked worker holds the motion stage (its copy of the session's, made when the run
  starts) and computes the next tick's reference, from the next tick's operator row and this tick's state, while
  this process runs this tick's controller and physics. Used with the operator side prefetched (prefetch.py),
  under the same conditions: its rows are known a tick ahead.

Values cross the pipe as float64 rows, packed and unpacked by field (pickling them would cost more than a third of
the motion stage). The worker's arrays are laid out as the engine's reading lays them out (the link table's columns
as views of one array), so that every computation on them is the same to the last bit; a test runs both ways and
compares the tick logs.
"""

from __future__ import annotations

import multiprocessing
import pickle
from multiprocessing.connection import Connection

import numpy as np

from stylesync.errors import StylesyncError
from stylesync.model.character import JOINT_NAMES, LINK_NAMES
from stylesync.model.state import CharacterState, MassProperties
from stylesync.motion.bounds import BoundsMonitor
from stylesync.motion.operator_analysis import OperatorAnalysis
from stylesync.motion.pose_optimization import MotionOptimizer
from stylesync.motion.reference import LipmMap, MotionReading, ReferencePose
from stylesync.motion.stance_fsm import Stance
from stylesync.motion.style_features import ROW_NAMES, StyleFeatures
from stylesync.prefetch import row_layout, start_forked, worker_signals
from stylesync.prefetch import unpack as unpack_operator
from stylesync.processing.operator_processing import OperatorSample

WORKER_EXIT_TIMEOUT_S = 2.0
STEP_BOUND = "step_length"  # the one movement bound the motion stage reports (Eq. 28)

_SIDES = ("left", "right")
_FEET = ("left_ankle", "right_ankle")
_STANCES = (Stance.LS, Stance.RS, Stance.DS)
_NJ, _NL = len(JOINT_NAMES), len(LINK_NAMES)


# The character's state: the link table in the engine reading's columns (COM 0:3, origin 3:6, COM velocity 10:13,
# angular velocity 13:16; 6:10 unused here), then the rest.
_STATE, STATE_WIDTH = row_layout([
    ("time_s", 1), ("root_pos", 3), ("root_quat", 4), ("root_lin_vel", 3), ("root_ang_vel", 3),
    ("joint_pos", 4 * _NJ), ("joint_vel", 3 * _NJ), ("table", 16 * _NL), ("link_quat", 4 * _NL),
    ("foot_force", len(_FEET)), ("non_foot", 1)])

# The reference pose and the operator's reading of one tick. Optional values carry a presence flag first.
_REF, REF_WIDTH = row_layout([
    ("time_s", 1), ("joint_pos", 4 * _NJ), ("root_quat", 4), ("pelvis", 3), ("com", 3), ("com_vel", 3),
    ("stance", 1), ("weight", 2), ("ankle", 6), ("lipm", 9), ("press", 1), ("hand", 7),
    ("own_ankle", 9), ("own_ankle_vel", 9), ("while_he_stands", 1), ("pelvis_vel_z", 1), ("way_speed", 1),
    ("stands_still", 1), ("op_stance", 1), ("features", len(ROW_NAMES)), ("held", 1), ("scale", 1),
    ("step_exceeded", 1), ("bound_count", 1)])


def pack_state(state: CharacterState) -> np.ndarray:
    """(STATE_WIDTH,) float64 row of the character's state."""
    row = np.zeros(STATE_WIDTH)
    row[0] = state.time_s
    row[_STATE["root_pos"]] = state.root_pos_world
    row[_STATE["root_quat"]] = state.root_quat_wxyz
    row[_STATE["root_lin_vel"]] = state.root_lin_vel_world
    row[_STATE["root_ang_vel"]] = state.root_ang_vel_world
    row[_STATE["joint_pos"]] = state.joint_pos.reshape(-1)
    row[_STATE["joint_vel"]] = state.joint_vel.reshape(-1)
    table = row[_STATE["table"]].reshape(_NL, 16)
    table[:, 0:3] = state.link_com_world
    table[:, 3:6] = state.link_origin_world
    table[:, 10:13] = state.link_com_vel_world
    table[:, 13:16] = state.link_ang_vel_world
    row[_STATE["link_quat"]] = state.link_quat_wxyz.reshape(-1)
    row[_STATE["foot_force"]] = [state.foot_contact_force_n[f] for f in _FEET]
    row[_STATE["non_foot"]] = float(state.non_foot_ground_contact)
    return row


def unpack_state(row: np.ndarray) -> CharacterState:
    """The inverse of :func:`pack_state`, each array its own (the link table's columns views of one array, as the
    engine's reading makes them)."""
    table = row[_STATE["table"]].reshape(_NL, 16).copy()
    force = row[_STATE["foot_force"]].tolist()
    return CharacterState(
        time_s=float(row[0]),
        root_pos_world=row[_STATE["root_pos"]].copy(),
        root_quat_wxyz=row[_STATE["root_quat"]].copy(),
        root_lin_vel_world=row[_STATE["root_lin_vel"]].copy(),
        root_ang_vel_world=row[_STATE["root_ang_vel"]].copy(),
        joint_pos=row[_STATE["joint_pos"]].reshape(_NJ, 4).copy(),
        joint_vel=row[_STATE["joint_vel"]].reshape(_NJ, 3).copy(),
        link_com_world=table[:, 0:3],
        link_com_vel_world=table[:, 10:13],
        link_origin_world=table[:, 3:6],
        link_quat_wxyz=row[_STATE["link_quat"]].reshape(_NL, 4).copy(),
        link_ang_vel_world=table[:, 13:16],
        foot_contact_force_n=dict(zip(_FEET, force, strict=True)),
        non_foot_ground_contact=bool(row[_STATE["non_foot"]][0]),
    )


def _put_sides(row: np.ndarray, key: str, values: dict[str, np.ndarray] | None) -> None:
    """A per-side dict of 3-vectors that may lack sides, or be None: a presence flag and a vector per side."""
    out = row[_REF[key]]
    if values is None:
        return
    out[0] = 1.0
    for k, side in enumerate(_SIDES):
        if side in values:
            out[1 + k] = 1.0
            out[3 + 3 * k:6 + 3 * k] = values[side]


def _get_sides(row: np.ndarray, key: str) -> dict[str, np.ndarray] | None:
    v = row[_REF[key]]
    if v[0] == 0.0:
        return None
    return {side: v[3 + 3 * k:6 + 3 * k].copy() for k, side in enumerate(_SIDES) if v[1 + k] != 0.0}


def pack_reference(ref: ReferencePose, reading: MotionReading, bound_count: int) -> np.ndarray:
    """(REF_WIDTH,) float64 row of one tick's reference pose, the operator's reading and the number of ticks the
    step-length bound has been exceeded so far."""
    row = np.zeros(REF_WIDTH)
    row[0] = ref.time_s
    row[_REF["joint_pos"]] = ref.joint_pos.reshape(-1)
    row[_REF["root_quat"]] = ref.root_quat_wxyz
    row[_REF["pelvis"]] = ref.pelvis_world
    row[_REF["com"]] = ref.com_world
    row[_REF["com_vel"]] = ref.com_vel_world
    row[_REF["stance"]] = _STANCES.index(ref.character_stance)
    row[_REF["weight"]] = [ref.stance_weight[s] for s in _SIDES]
    row[_REF["ankle"]] = np.concatenate([ref.ankle_world[s] for s in _SIDES])
    if ref.lipm is not None:
        lp = ref.lipm
        row[_REF["lipm"]] = [1.0, *lp.d_a_human, lp.h_human_m, *lp.d_a_char, lp.h_char_m]
    row[_REF["press"]] = float(ref.press_swing_foot)
    if ref.hand_world is not None:
        row[_REF["hand"]] = [1.0, *ref.hand_world["left"], *ref.hand_world["right"]]
    _put_sides(row, "own_ankle", ref.recovery_ankle_world)  # (a step of its own: one side)
    _put_sides(row, "own_ankle_vel", ref.recovery_ankle_vel_world)
    row[_REF["while_he_stands"]] = float(ref.recovery_while_he_stands)
    row[_REF["pelvis_vel_z"]] = ref.pelvis_vel_z_mps
    row[_REF["way_speed"]] = ref.his_way_speed_mps
    row[_REF["stands_still"]] = float(ref.both_stand_still)
    row[_REF["op_stance"]] = _STANCES.index(reading.operator_stance)
    row[_REF["features"]] = reading.operator_features.as_row()
    row[_REF["held"]] = float(reading.held)
    row[_REF["scale"]] = reading.scale
    row[_REF["step_exceeded"]] = float(reading.step_bound_exceeded)
    row[_REF["bound_count"]] = bound_count
    return row


def unpack_reference(row: np.ndarray) -> tuple[ReferencePose, MotionReading, int]:
    """The inverse of :func:`pack_reference`."""
    lp = row[_REF["lipm"]]
    hand = row[_REF["hand"]]
    weight = row[_REF["weight"]].tolist()
    ankle = row[_REF["ankle"]]
    ref = ReferencePose(
        time_s=float(row[0]),
        joint_pos=row[_REF["joint_pos"]].reshape(_NJ, 4).copy(),
        root_quat_wxyz=row[_REF["root_quat"]].copy(),
        pelvis_world=row[_REF["pelvis"]].copy(),
        com_world=row[_REF["com"]].copy(),
        com_vel_world=row[_REF["com_vel"]].copy(),
        character_stance=_STANCES[int(row[_REF["stance"]][0])],
        stance_weight=dict(zip(_SIDES, weight, strict=True)),
        ankle_world={"left": ankle[0:3].copy(), "right": ankle[3:6].copy()},
        lipm=None if lp[0] == 0.0 else LipmMap(lp[1:4].copy(), float(lp[4]), lp[5:8].copy(), float(lp[8])),
        press_swing_foot=bool(row[_REF["press"]][0]),
        hand_world=None if hand[0] == 0.0 else {"left": hand[1:4].copy(), "right": hand[4:7].copy()},
        recovery_ankle_world=_get_sides(row, "own_ankle"),
        recovery_ankle_vel_world=_get_sides(row, "own_ankle_vel"),
        recovery_while_he_stands=bool(row[_REF["while_he_stands"]][0]),
        pelvis_vel_z_mps=float(row[_REF["pelvis_vel_z"]][0]),
        his_way_speed_mps=float(row[_REF["way_speed"]][0]),
        both_stand_still=bool(row[_REF["stands_still"]][0]),
    )
    reading = MotionReading(_STANCES[int(row[_REF["op_stance"]][0])],
                            StyleFeatures.from_row(row[_REF["features"]].copy()), bool(row[_REF["held"]][0]),
                            float(row[_REF["scale"]][0]), bool(row[_REF["step_exceeded"]][0]))
    return ref, reading, int(row[_REF["bound_count"]][0])


class MotionInline:
    """The motion stage in this process, on this tick's state or, ``on_last_state``, on the last tick's (see the
    module's notes)."""

    def __init__(self, motion: MotionOptimizer, mass: MassProperties, on_last_state: bool):
        self.motion = motion
        self.mass = mass
        self.on_last_state = on_last_state
        self._last_state: CharacterState | None = None

    def reference(self, sample: OperatorSample, analysis: OperatorAnalysis | None,
                  state: CharacterState) -> tuple[ReferencePose, MotionReading]:
        """This tick's reference and the operator's reading, from this tick's sample and this tick's state, or the
        last tick's (at the first tick, this tick's)."""
        basis = state
        if self.on_last_state:
            basis = state if self._last_state is None else self._last_state
            self._last_state = state
        ref = self.motion.update(sample, basis, self.mass, analysis)
        reading = self.motion.reading
        assert reading is not None  # the motion stage has run
        return ref, reading

    def close(self) -> None:
        """Nothing to release."""


def _worker(conn: Connection, session_end: Connection, motion: MotionOptimizer, mass: MassProperties) -> None:
    """The forked process: one reference per request, until the session closes its end."""
    session_end.close()  # (as prefetch._worker: a session that dies leaves no writer, and recv ends)
    worker_signals()
    try:
        while True:
            message = conn.recv_bytes()  # b"bounds", or a state row and an operator row
            if message == b"bounds":
                conn.send_bytes(b"B" + pickle.dumps(motion.bounds.first.get(STEP_BOUND)))
                continue
            row = np.frombuffer(message)
            try:
                sample, analysis, _, _ = unpack_operator(row[STATE_WIDTH:])
                ref = motion.update(sample, unpack_state(row[:STATE_WIDTH]), mass, analysis)
                reading = motion.reading
                assert reading is not None
                out = pack_reference(ref, reading, motion.bounds.counts[STEP_BOUND])
            except Exception as exc:  # raised by the session at the tick that asked
                try:
                    conn.send_bytes(b"E" + pickle.dumps(exc))
                except Exception:
                    conn.send_bytes(b"E" + pickle.dumps(StylesyncError(f"motion stage: {type(exc).__name__}: {exc}")))
                return
            conn.send_bytes(b"R" + out.tobytes())
    except (BrokenPipeError, EOFError, OSError):  # the session has gone
        return


class MotionAhead:
    """The motion stage in a forked worker, a tick ahead of the controller (see the module's notes). Its copy of
    ``motion`` is made now; the session's own is not advanced. ``bounds`` gets the step-length bound's record."""

    def __init__(self, motion: MotionOptimizer, mass: MassProperties, bounds: BoundsMonitor):
        ctx = multiprocessing.get_context("fork")
        self._conn, child = ctx.Pipe(duplex=True)
        self._proc = ctx.Process(target=_worker, args=(child, self._conn, motion, mass), name="stylesync-motion",
                                 daemon=True)
        start_forked(self._proc)
        child.close()
        self._bounds = bounds
        self._pending = False
        self._first = True

    def reference(self, operator_row: np.ndarray, next_operator_row: np.ndarray | None,
                  state: CharacterState) -> tuple[ReferencePose, MotionReading]:
        """This tick's reference and the operator's reading (computed during the last tick; at the first, now), and
        the next tick's asked for from ``next_operator_row`` (None: this is the last) and this tick's state."""
        if self._first:
            self._first = False
            self._send(operator_row, state)
        ref, reading = self._receive()
        if next_operator_row is not None:
            self._send(next_operator_row, state)
        return ref, reading

    def _send(self, operator_row: np.ndarray, state: CharacterState) -> None:
        self._conn.send_bytes(np.concatenate([pack_state(state), operator_row]).tobytes())
        self._pending = True

    def _receive(self) -> tuple[ReferencePose, MotionReading]:
        try:
            message = self._conn.recv_bytes()
        except (EOFError, OSError):
            raise StylesyncError("the motion-stage process ended unexpectedly") from None
        self._pending = False
        if message[:1] == b"E":
            raise pickle.loads(message[1:])
        ref, reading, count = unpack_reference(np.frombuffer(message, offset=1).copy())
        self._bounds.active[STEP_BOUND] = reading.step_bound_exceeded
        self._bounds.counts[STEP_BOUND] = count
        return ref, reading

    def close(self) -> None:
        """Take the worker's first excess of the step-length bound (when the ticks used exceeded it), end the
        worker and release the pipe. A reference asked for and not used (the run ended first) is dropped."""
        try:
            if self._proc.is_alive():
                if self._pending:
                    self._conn.recv_bytes()
                    self._pending = False
                self._conn.send_bytes(b"bounds")
                message = self._conn.recv_bytes()
                if message[:1] == b"B" and self._bounds.counts[STEP_BOUND] > 0:
                    first = pickle.loads(message[1:])
                    if first is not None:
                        self._bounds.first.setdefault(STEP_BOUND, first)
        except (EOFError, OSError):
            pass
        self._conn.close()
        if self._proc.is_alive():
            self._proc.terminate()
        self._proc.join(WORKER_EXIT_TIMEOUT_S)

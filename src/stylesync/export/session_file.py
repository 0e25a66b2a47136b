"""Session files: an open, line-based record of a run, flushed as it goes.

Format (UTF-8 JSON Lines). The first line is a header ``{"format": "stylesync-session", "version": 1, "config":
{...}, "joints": [...], "links": [...], "operator_joints": [...], "stance_codes": {...}}``. Then one line per control
tick: ``t`` [s], ``root_pos_world`` [3], ``root_quat_wxyz`` [4], ``joint_pos`` [n_joints][4] (ball joints wxyz in
model axes, hinge angle first; with the root pose they fix every link), ``link_quat_wxyz`` [n_links][4] (canonical),
``torques_nm`` [n_joints][3] (ball: child frame; hinge: first), ``scale`` (Eq. 9),
``operator_stance`` and ``character_stance``
(LS/DS/RS), ``operator_features`` [7], ``character_com_world`` [3], ``operator_pos`` [n_operator_joints][3],
and, in a run paced to the wall clock (``wall_clock=True``), ``monotonic_s``: the host's monotonic clock when the
tick ran [s], to align the run with other records of the same machine, such as a viewer's or a sender's. It is not
part of the replayed state, and it is left out of unpaced runs, whose files are byte-identical from run to run.
The last line, when the run ends, is ``{"metrics": {...}}``. Floats are written with Python's shortest exact
representation, so a replay reads back identical states. Units: m, s, rad, N·m; world frame z up. Lines are
flushed every 50 ticks, so a run cut short leaves a readable file.

A recorder may defer the writing (``deferred=True``, for runs as fast as possible): each tick then keeps references
to its values (arrays the session never changes once made), and the lines are written when the run ends, the
same lines. Formatting a line costs about 0.2 ms, a sixth of the control tick; an offline run can be run again if
it is cut short. At most MAX_DEFERRED_TICKS are held; beyond, the lines are written as they come.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, NamedTuple

import numpy as np

from stylesync.errors import SourceError
from stylesync.model.character import JOINTS, LINK_NAMES
from stylesync.processing.joint_map import TRACKED_POSITIONS

log = logging.getLogger("stylesync.export")

FORMAT = "stylesync-session"
VERSION = 1
FLUSH_EVERY_TICKS = 50
MAX_DEFERRED_TICKS = 100_000  # about 12 minutes at 133 Hz, some 100 MB of references


class _TickValues(NamedTuple):
    """What one tick's line is written from: references to values the session never changes once made."""

    t: float
    root_pos_world: np.ndarray
    root_quat_wxyz: np.ndarray
    joint_pos: np.ndarray
    link_quat_wxyz: np.ndarray
    torques_nm: np.ndarray | None
    scale: float
    operator_stance: Any
    character_stance: Any
    operator_features: Any
    character_com_world: np.ndarray | None
    sample: Any  # the operator sample, for its joint positions
    monotonic_s: float | None  # the host's monotonic clock when the tick ran [s] (paced runs only)


class SessionRecorder:
    """Writes a session file; ``tick`` is the session's ``on_tick`` hook."""

    def __init__(self, path: str | Path, config: Any, session: Any, deferred: bool = False,
                 run_id: str | None = None, wall_clock: bool = False):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._f: IO[str] = self.path.open("w", encoding="utf-8")
        self._session = session
        self._n = 0
        self.deferred = deferred
        self.wall_clock = wall_clock  # each tick's line says when it ran (monotonic_s)
        self._held: list[_TickValues] = []  # deferred ticks' values
        header = {"format": FORMAT, "version": VERSION,
                  "config": _config_dict(config),
                  "joints": [j.name for j in JOINTS], "links": list(LINK_NAMES),
                  "operator_joints": list(TRACKED_POSITIONS), "stance_codes": {"LS": 0, "DS": 1, "RS": 2}}
        if run_id is not None:
            header["run_id"] = run_id  # also in the run's metrics.json: which outputs belong together
        self._write(header)
        self._f.flush()

    def _write(self, obj: dict) -> None:
        self._f.write(json.dumps(obj, default=_jsonable) + "\n")

    def tick(self, state: Any, ref: Any) -> None:
        sess = self._session
        reading = sess.reading
        values = _TickValues(state.time_s, state.root_pos_world, state.root_quat_wxyz, state.joint_pos,
                             state.link_quat_wxyz, getattr(sess, "last_torques", None), reading.scale,
                             reading.operator_stance, ref.character_stance, reading.operator_features,
                             getattr(sess, "last_com_world", None), getattr(sess, "last_sample", None),
                             time.monotonic() if self.wall_clock else None)
        if self.deferred and len(self._held) < MAX_DEFERRED_TICKS:
            self._held.append(values)
            return
        self._write_held()
        self._write_tick(values)

    def _write_held(self) -> None:
        for values in self._held:
            self._write_tick(values)
        self._held = []

    def _write_tick(self, v: _TickValues) -> None:
        line = {
            "t": v.t, "root_pos_world": v.root_pos_world.tolist(),
            "root_quat_wxyz": v.root_quat_wxyz.tolist(), "joint_pos": v.joint_pos.tolist(),
            "link_quat_wxyz": v.link_quat_wxyz.tolist(),
            "torques_nm": None if v.torques_nm is None else np.asarray(v.torques_nm).tolist(),
            "scale": v.scale, "operator_stance": v.operator_stance.value,
            "character_stance": v.character_stance.value,
            "operator_features": list(v.operator_features.as_row()),
            "character_com_world": v.character_com_world,
            "operator_pos": None if v.sample is None else [v.sample.pos[n].tolist() for n in TRACKED_POSITIONS],
        }
        if v.monotonic_s is not None:
            line["monotonic_s"] = v.monotonic_s
        self._write(line)
        self._n += 1
        if self._n % FLUSH_EVERY_TICKS == 0:
            self._f.flush()

    def close(self, metrics: dict | None = None) -> None:
        if self._f.closed:
            return
        self._write_held()
        if metrics is not None:
            self._write({"metrics": metrics})
        self._f.close()


def _config_dict(config: Any) -> Any:
    if dataclasses.is_dataclass(config) and not isinstance(config, type):
        return dataclasses.asdict(config)
    return config


def _jsonable(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, Path):
        return str(o)
    if hasattr(o, "value"):
        return o.value
    raise TypeError(f"not serialisable: {type(o).__name__}")


@dataclasses.dataclass
class SessionFile:
    header: dict
    ticks: list[dict]
    metrics: dict | None
    bad_line: str | None = None  # where and why the reading stopped before the end of the file

    def array(self, key: str) -> np.ndarray:
        return np.asarray([t[key] for t in self.ticks], dtype=float)


def iter_lines(path: Path) -> Iterator[tuple[int, dict]]:
    with path.open("r", encoding="utf-8") as f:
        for k, line in enumerate(f, start=1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError:
                raise SourceError(f"session file {path}, line {k}: not JSON (truncated or damaged)") from None
            if not isinstance(obj, dict):
                raise SourceError(f"session file {path}, line {k}: expected a JSON object")
            yield k, obj


# A tick's state: these keys must hold finite numbers (nested lists) of these shapes' sizes.
_TICK_ARRAYS = {"root_pos_world": 3, "root_quat_wxyz": 4, "joint_pos": 4 * len(JOINTS),
                "link_quat_wxyz": 4 * len(LINK_NAMES)}
MAX_TICK_GAP_S = 1.0  # consecutive ticks further apart than this are damage (control ticks are ~7.5 ms apart) [s]


def _tick_problem(obj: dict, last_t: float) -> str | None:
    """Why a tick line cannot be replayed (None: it can): time not finite, not after the previous tick or jumping
    by more than MAX_TICK_GAP_S, a state array missing, of the wrong size or not finite."""
    try:
        t = float(obj["t"])
    except (TypeError, ValueError, OverflowError):
        return "time is not a number"
    if not np.isfinite(t):
        return "time is not finite"
    if t <= last_t:
        return f"time {t:g} s not after {last_t:g} s"
    if np.isfinite(last_t) and t - last_t > MAX_TICK_GAP_S:
        return f"time jumps from {last_t:g} s to {t:g} s"
    for key, size in _TICK_ARRAYS.items():
        if key not in obj:
            continue  # older files may lack link rotations; the replay then says what is missing
        try:
            values = np.asarray(obj[key], dtype=float)
        except (TypeError, ValueError, OverflowError):
            return f"{key} is not numeric"
        if values.size != size:
            return f"{key} has {values.size} values, not {size}"
        if not np.all(np.isfinite(values)):
            return f"{key} is not finite"
    return None


def read_session(path: str | Path) -> SessionFile:
    """Read a session file. A run cut short (no metrics line, a truncated last line) keeps its complete ticks; a
    damaged line (not JSON, not a tick, a state that is not finite, time not increasing or jumping) ends the
    reading there: the ticks before it are kept and ``bad_line`` says which line and why (logged once)."""
    p = Path(path)
    if not p.is_file():
        raise SourceError(f"session file not found: {p}")
    header: dict | None = None
    ticks: list[dict] = []
    metrics = None
    bad: str | None = None
    last_t = -np.inf
    try:
        for k, obj in iter_lines(p):
            if header is None:
                if obj.get("format") != FORMAT:
                    raise SourceError(f"{p} is not a stylesync session file (no '{FORMAT}' header)")
                header = obj
            elif "metrics" in obj:
                metrics = obj["metrics"]
            elif "t" in obj and "root_pos_world" in obj:
                problem = _tick_problem(obj, last_t)
                if problem is not None:
                    bad = f"line {k}: {problem}"
                    break
                ticks.append(obj)
                last_t = float(obj["t"])
            else:
                bad = f"line {k}: neither a tick nor the metrics"
                break
    except SourceError as exc:
        if header is None or "not JSON" not in str(exc):
            raise
        bad = str(exc).split(", ", 1)[-1]
    except UnicodeDecodeError:
        raise SourceError(f"session file {p} is not UTF-8 text") from None
    if header is None:
        raise SourceError(f"session file {p} is empty")
    if bad is not None:
        log.warning("session file %s, %s: replaying the %d ticks before it", p, bad, len(ticks))
    return SessionFile(header, ticks, metrics, bad)

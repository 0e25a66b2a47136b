"""Attach a viewer to a running session or to a replayed session file.

``--viewer web`` serves the browser viewer (web_viewer.py); ``--viewer gui`` opens a PyBullet window that mirrors
the simulated character kinematically from a thread of its own, so the physics keeps stepping in DIRECT mode at
full speed whatever the window's frame rate.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import numpy as np

from stylesync.config import VIEWER_DRAW_HZ, WorldConfig
from stylesync.errors import SimulationError
from stylesync.motion.stance_fsm import Stance
from stylesync.sim.disturbance import throw_ball_at_chest
from stylesync.sim.factory import make_backend
from stylesync.viewer.snapshot import Snapshot, snapshot_from_state

log = logging.getLogger("stylesync.viewer")

class GuiMirror:
    """A PyBullet GUI window posed from snapshots at ``draw_hz``; it never steps (nothing simulated there)."""

    def __init__(self, draw_hz: float = 30.0):
        self.backend = make_backend(WorldConfig(), 600.0, gui=True)  # raises SimulationError without a display
        self.draw_hz = draw_hz
        self.url = "PyBullet window"
        self._latest: Snapshot | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="stylesync-gui-mirror", daemon=True)
        self._thread.start()

    def publish(self, snap: Snapshot) -> None:
        self._latest = snap

    def _loop(self) -> None:
        drawn = None
        while not self._stop.wait(1.0 / self.draw_hz):
            snap = self._latest
            if snap is not None and snap is not drawn:
                self.backend.reset(snap.root_pos_world, snap.root_quat_wxyz, snap.joint_pos)
                drawn = snap

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.backend.close()


def open_viewer(kind: str, session=None, host: str = "127.0.0.1", port: int | None = None,
                draw_hz: float = VIEWER_DRAW_HZ):
    """A viewer of ``kind`` ('web' or 'gui'); with ``session`` its controls act on that session."""
    if kind == "gui":
        try:
            return GuiMirror(draw_hz)
        except SimulationError as exc:
            raise SimulationError(f"--viewer gui needs a display ({exc}); use --viewer web on a headless machine")\
                from exc
    from stylesync.viewer.process import ViewerProcess

    if session is None:
        backend = make_backend(WorldConfig(), 600.0)
        shapes = backend.collision_shapes()
        backend.close()
        return ViewerProcess(shapes, host, port, draw_hz)
    return ViewerProcess(session.backend.collision_shapes(), host, port, draw_hz,
                         on_action=lambda action: apply_action(session, action))


def apply_action(session, action: str) -> None:
    """A viewer control's action on a running session (called from any thread)."""
    if action == "pause":
        session.paused = True
    elif action == "resume":
        session.paused = False
    elif action == "reset":
        session.commands.put(lambda s: s.reset_character())
    elif action == "push":
        session.commands.put(lambda s: throw_ball_at_chest(s.backend, s.backend.read_state(0.0)))
    else:
        log.warning("viewer: unknown action %r ignored", action)


def session_hook(session, viewer, draw_hz: float) -> Callable:
    """An ``on_tick`` hook that hands the viewer a snapshot, at most once per drawn frame (wall clock)."""
    min_gap = 1.0 / draw_hz
    last = [-np.inf]

    def hook(state, ref) -> None:
        now = time.perf_counter()
        if now - last[0] < min_gap:
            return
        last[0] = now
        sample = session.last_sample
        com = session.last_com_world if session.last_com_world is not None else session.mass.com(state)
        balls = tuple(session.backend.body_position(b) for b in getattr(session.backend, "balls", []))
        viewer.publish(snapshot_from_state(
            state, com, ref.character_stance, session.reading.operator_stance,
            None if sample is None else sample.pos, session.reading.scale, session.bounds.active, balls,
            fell=session.fell))

    return hook


def chain(*hooks: Callable | None) -> Callable:
    live = [h for h in hooks if h is not None]

    def call(state, ref) -> None:
        for h in live:
            h(state, ref)

    return call


def replay_snapshots(ticks: list[dict], operator_joints: list[str]):
    """Snapshots of a recorded session, posing the character kinematically (no simulation)."""
    from stylesync.export.replay import posed_backend

    for tk, backend in posed_backend(ticks):
        state = backend.read_state(float(tk["t"]))
        ch, op = Stance(tk["character_stance"]), Stance(tk["operator_stance"])
        feet = {"left": ch is not Stance.RS, "right": ch is not Stance.LS}
        op_pos = None if tk.get("operator_pos") is None else dict(zip(operator_joints, tk["operator_pos"],
                                                                      strict=True))
        com = tk.get("character_com_world") or backend.mass_properties().com(state)
        yield snapshot_from_state(state, np.asarray(com), ch, op, op_pos, float(tk.get("scale", 0.8)),
                                  {}, feet_down=feet)

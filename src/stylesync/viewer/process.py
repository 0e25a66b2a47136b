"""The web viewer in a process of its own, so that serving and drawing never compete with the control loop for
the interpreter (measured: in-process, the viewer's threads took 14-41 % of the loop's realtime factor; see
benchmarks/viewer_overhead.py).

The session's process sends snapshots through a bounded queue (a full queue drops the snapshot: the viewer only
ever wants the newest) and receives the controls' named actions through another, read by a small thread that
turns them into session commands.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
import queue
import threading
from collections.abc import Callable
from typing import Any

from stylesync.errors import ConfigError
from stylesync.model.state import LinkShape
from stylesync.viewer.snapshot import Snapshot

log = logging.getLogger("stylesync.viewer")
START_TIMEOUT_S = 60.0
_STOP = "stop"
VIEWER_NICENESS = 10  # added to the viewer process's niceness
PARENT_CHECK_S = 1.0  # how often an idle viewer process checks that the session's process is still there [s]


def _serve(shapes: list[LinkShape], host: str, port: int, draw_hz: float, interactive: bool,
           snapshots: mp.Queue, actions: mp.Queue, ready: Any, parent_pid: int, token: str) -> None:
    from stylesync.viewer.web_viewer import WebViewer

    # The viewer yields to the control loop when they compete for a core: a late frame is harmless, a late
    # control tick is not.
    os.nice(VIEWER_NICENESS)
    viewer = WebViewer(shapes, host, port, draw_hz, on_action=actions.put if interactive else None, token=token)
    ready.set()
    try:
        while True:
            try:
                item = snapshots.get(timeout=PARENT_CHECK_S)
            except queue.Empty:
                # A session killed by a signal never sends the stop, and multiprocessing only ends daemonic
                # children at a normal exit: an orphaned viewer (re-parented) would otherwise serve forever.
                if os.getppid() != parent_pid:
                    break
                continue
            if item == _STOP:
                break
            viewer.publish(item)
    except (KeyboardInterrupt, EOFError, OSError):
        pass
    finally:
        viewer.close()


def ipaddress_is_loopback(host: str) -> bool:
    """Whether a listening address is this machine's own (127.0.0.0/8, ::1, localhost)."""
    import ipaddress

    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class ViewerProcess:
    """``publish(snapshot)`` from the loop; ``on_action`` (called in a thread of this process) gets the actions."""

    def __init__(self, shapes: list[LinkShape], host: str = "127.0.0.1", port: int | None = None,
                 draw_hz: float = 20.0, on_action: Callable[[str], None] | None = None):
        from stylesync.viewer.access import new_token
        from stylesync.viewer.web_viewer import free_port, import_viser

        import_viser()  # fail here, with the install hint, rather than in the child

        ctx = mp.get_context("spawn")
        self.port = port if port else free_port(host)
        token = new_token()
        self.url = f"http://{host}:{self.port}/?token={token}"
        if not ipaddress_is_loopback(host):
            log.warning("the web viewer listens on %s: anyone on that network who has its address (with the token) "
                        "can watch and control the run", host)
        self._snapshots: mp.Queue = ctx.Queue(maxsize=2)
        self._actions: mp.Queue = ctx.Queue()
        ready = ctx.Event()
        self._proc = ctx.Process(target=_serve, name="stylesync-viewer", daemon=True,
                                 args=(shapes, host, self.port, draw_hz, on_action is not None, self._snapshots,
                                       self._actions, ready, os.getpid(), token))
        self._proc.start()
        if not ready.wait(START_TIMEOUT_S) or not self._proc.is_alive():
            self._proc.terminate()
            raise ConfigError(f"the web viewer did not start on {self.url}")
        self._on_action = on_action
        self.published = 0  # snapshots handed to the viewer process
        self._reader: threading.Thread | None = None
        if on_action is not None:
            self._reader = threading.Thread(target=self._read_actions, name="stylesync-viewer-actions", daemon=True)
            self._reader.start()

    def _read_actions(self) -> None:
        while True:
            try:
                action = self._actions.get()
            except (EOFError, OSError):
                return
            if action == _STOP:
                return
            if self._on_action is not None:
                self._on_action(action)

    def publish(self, snap: Snapshot) -> None:
        try:
            self._snapshots.put_nowait(snap)
            self.published += 1
        except queue.Full:
            pass  # the viewer is behind; it will draw a newer snapshot

    def close(self) -> None:
        if self._proc.is_alive():
            try:
                self._snapshots.put(_STOP, timeout=1.0)
            except queue.Full:
                pass
            self._proc.join(timeout=5.0)
            if self._proc.is_alive():
                self._proc.terminate()
        self._actions.put(_STOP)
        if self._reader is not None:
            self._reader.join(timeout=1.0)

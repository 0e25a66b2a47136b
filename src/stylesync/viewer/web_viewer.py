"""Live 3D viewer in the browser (viser): the character's collision shapes, the operator's skeleton, the COM and its
ground projection, the support polygon, the stance state, the movement bounds of Eq. 24-28 with a warning when the
operator exceeds them, live plots of the COM and the stance, and controls (pause, reset, push, overlays, camera
follow).

The viewer runs in a process of its own (process.py) and draws the newest :class:`Snapshot` it has received at
``draw_hz`` from a thread; the control loop only sends it snapshots. Button presses never touch the engine from
here: they become named actions that the session's process turns into commands run at its next control tick.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections import deque
from collections.abc import Callable

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import ConfigError
from stylesync.model.state import LinkShape
from stylesync.motion.stance_fsm import Stance
from stylesync.viewer import access
from stylesync.viewer.snapshot import (
    OPERATOR_BONES,
    Snapshot,
    bound_circles,
    operator_overlay,
    shape_poses,
    support_polygon,
)

log = logging.getLogger("stylesync.viewer")
PLOT_WINDOW_S = 10.0  # live plots show this much history [s]
PLOT_EVERY_S = 0.25  # live plots are redrawn at most this often [s]
TEXT_EVERY_S = 0.05  # status and warning texts are refreshed at most this often [s]
CAMERA_DEADBAND_M = 0.05  # a following camera moves once the COM has moved this far [m]
OPERATOR_BESIDE_M = np.array([0.0, 0.9, 0.0])  # operator skeleton beside the character (world, +y) [m]
CAMERA_OFFSET_M = (2.6, -1.6, 1.4)  # camera position relative to the COM's ground point [m]
_CIRCLE = np.stack([np.cos(np.linspace(0, 2 * np.pi, 49)), np.sin(np.linspace(0, 2 * np.pi, 49))], axis=1)
_STANCE_TEXT = {Stance.LS: "LS (left stance)", Stance.DS: "DS (double stance)", Stance.RS: "RS (right stance)"}
_BODY_COLOUR = (200, 180, 150)
_OK, _WARN = (60, 160, 60), (230, 40, 40)


def free_port(host: str = "127.0.0.1") -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def _shape_mesh(shape: LinkShape) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (in the shape's frame) and faces of a collision shape."""
    import trimesh

    if shape.kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=shape.size[0])
    elif shape.kind == "box":
        mesh = trimesh.creation.box(extents=shape.size)
    else:
        mesh = trimesh.creation.capsule(height=shape.size[0], radius=shape.size[1], count=[12, 12])
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.uint32)


def _aim(client, com_world: np.ndarray) -> None:
    """Point a browser's camera at the character from CAMERA_OFFSET_M beside its COM's ground point."""
    c = com_world
    client.camera.position = (c[0] + CAMERA_OFFSET_M[0], c[1] + CAMERA_OFFSET_M[1], CAMERA_OFFSET_M[2])
    client.camera.look_at = (c[0], c[1] + 0.4, 0.8)


def _ring_segments(points_2d: np.ndarray, z_m: float) -> np.ndarray:
    """Closed polyline through ``points_2d`` as (n, 2, 3) segments at height ``z_m``."""
    p = np.column_stack([points_2d, np.full(len(points_2d), z_m)])
    return np.stack([p, np.roll(p, -1, axis=0)], axis=1)


def import_viser():
    """viser and its uPlot module, or a ConfigError with the install hint."""
    try:
        import viser
        import viser.uplot as uplot
    except ImportError as exc:
        raise ConfigError(f"the web viewer needs viser ({exc}); install it with: pip install viser") from exc
    return viser, uplot


GROUND_SIZE_M = 20.0  # side of the floor grid [m]
GROUND_CELL_M = 0.5  # its cell [m]


class WebViewer:
    """``publish`` a snapshot; ``close`` when done. ``on_action`` receives the controls' actions by name ("reset",
    "push", "pause", "resume"); ``None`` makes the viewer read-only (replay). Runs in the viewer's own process
    (process.py)."""

    def __init__(self, shapes: list[LinkShape], host: str = "127.0.0.1", port: int | None = None,
                 draw_hz: float = 20.0, on_action: Callable[[str], None] | None = None, token: str | None = None):
        viser, uplot = import_viser()
        self.port = port if port else free_port(host)
        self.host = host
        self.token = token if token is not None else access.new_token()
        self.url = f"http://{host}:{self.port}/?token={self.token}"
        access.install(self.token)  # the page and its websocket need the token, from the page's own origin
        self.server = viser.ViserServer(host=host, port=self.port, verbose=False)
        self.shapes = shapes
        self.draw_hz = draw_hz
        self._on_action = on_action
        self._latest: Snapshot | None = None
        self._drawn: Snapshot | None = None
        self._stop = threading.Event()
        self._history: deque[tuple[float, float, float, float]] = deque()
        self._last_plot = 0.0
        self._last_text = 0.0
        self._camera_target = np.full(2, np.inf)
        self._build_scene()
        self._build_gui(uplot)
        self.server.on_client_connect(self._place_camera)
        self._thread = threading.Thread(target=self._loop, name="stylesync-web-viewer", daemon=True)
        self._thread.start()

    # ---- scene ----------------------------------------------------------------------------------------------
    def _build_scene(self) -> None:
        sc = self.server.scene
        sc.set_up_direction("+z")
        # Without a GPU the browser renders WebGL in software; a shadow map is a second render pass per frame.
        sc.configure_default_lights(enabled=True, cast_shadow=False)
        self._ground = sc.add_grid("/ground", width=GROUND_SIZE_M, height=GROUND_SIZE_M, cell_size=GROUND_CELL_M,
                                   position=(0.0, 0.0, 0.0))
        self._ground_at = np.zeros(2)
        # The whole body is one mesh whose vertices are re-posed each frame: one message per frame instead of two
        # per shape (the per-shape handles cost the loop measurably more).
        parts = [_shape_mesh(sh) for sh in self.shapes]
        self._local_vertices = [v for v, _ in parts]
        offsets = np.cumsum([0] + [len(v) for v in self._local_vertices[:-1]])
        faces = np.concatenate([f + o for (_, f), o in zip(parts, offsets, strict=True)]).astype(np.uint32)
        self._body = sc.add_mesh_simple("/character/body", np.concatenate(self._local_vertices), faces,
                                        color=_BODY_COLOUR)
        self._com = sc.add_icosphere("/overlays/com", radius=0.03, color=(220, 30, 30))
        self._com_ground = sc.add_icosphere("/overlays/com_ground", radius=0.025, color=(220, 30, 30),
                                            scale=(1.0, 1.0, 0.15))
        self._com_line = sc.add_line_segments("/overlays/com_drop", np.zeros((1, 2, 3)), (220, 30, 30),
                                              thickness=0.004)
        self._support = sc.add_line_segments("/overlays/support", np.zeros((1, 2, 3)), (30, 90, 220),
                                             thickness=0.008)
        self._bounds = sc.add_line_segments("/overlays/bounds", np.zeros((1, 2, 3)), _OK, thickness=0.006)
        self._operator = sc.add_line_segments("/overlays/operator", np.zeros((len(OPERATOR_BONES), 2, 3)),
                                              (40, 120, 200), thickness=0.02)
        self._stance_label = sc.add_label("/overlays/stance", "DS", position=(0.0, 0.0, 1.9))
        self._label_stance = Stance.DS
        self._balls: list = []

    def _build_gui(self, uplot) -> None:
        gui = self.server.gui
        self._status = gui.add_markdown("**t = 0.00 s**")
        self._warning = gui.add_markdown("")
        self._pause = gui.add_checkbox("Pause", initial_value=False)
        self._follow = gui.add_checkbox("Camera follow", initial_value=True)
        reset = gui.add_button("Reset character")
        push = gui.add_button("Push (throw a ball at the chest)")
        with gui.add_folder("Overlays"):
            self._show = {k: gui.add_checkbox(label, initial_value=True) for k, label in (
                ("operator", "Operator skeleton"), ("com", "COM and its ground point"),
                ("support", "Support polygon"), ("bounds", "Movement bounds (Eq. 24, 28)"),
                ("stance", "Stance state"))}
            self._overlay_mode = gui.add_dropdown("Operator", ("beside", "overlaid"), initial_value="beside")
        empty = (np.zeros(1), np.zeros(1), np.zeros(1))
        linear_x = {"x": uplot.Scale(time=False)}
        self._com_plot = gui.add_uplot(
            data=empty, series=(uplot.Series(label="t [s]"), uplot.Series(label="COM x [m]", stroke="red"),
                                uplot.Series(label="COM y [m]", stroke="blue")), title="COM", aspect=2.0,
            scales=linear_x)
        self._stance_plot = gui.add_uplot(
            data=(np.zeros(1), np.zeros(1)), series=(uplot.Series(label="t [s]"),
                                                     uplot.Series(label="stance (0 LS, 1 DS, 2 RS)", stroke="green")),
            title="Character stance", aspect=2.0, scales=linear_x)
        if self._on_action is None:
            for h in (reset, push):
                h.disabled = True
        else:
            act = self._on_action
            reset.on_click(lambda _: act("reset"))
            push.on_click(lambda _: act("push"))
            self._pause.on_update(lambda _: act("pause" if self._pause.value else "resume"))

    def _place_camera(self, client) -> None:
        snap = self._latest
        _aim(client, snap.com_world if snap is not None else np.zeros(3))

    def publish(self, snap: Snapshot) -> None:
        self._latest = snap

    # ---- the viewer's thread -------------------------------------------------------------------------------
    def _loop(self) -> None:
        period = 1.0 / self.draw_hz
        while not self._stop.is_set():
            t0 = time.perf_counter()
            snap = self._latest
            if snap is not None and snap is not self._drawn:
                try:
                    self._draw(snap)
                except Exception:  # a drawing error must not take the session down
                    log.exception("web viewer: drawing failed")
                self._drawn = snap
            self._stop.wait(max(0.0, period - (time.perf_counter() - t0)))

    def _draw(self, snap: Snapshot) -> None:
        show = {k: h.value for k, h in self._show.items()}
        with self.server.atomic():
            posed = [v @ rot.matrix_from_quat(q).T + p
                     for v, (p, q) in zip(self._local_vertices, shape_poses(self.shapes, snap), strict=True)]
            self._body.vertices = np.concatenate(posed).astype(np.float32)
            com = snap.com_world
            for handle in (self._com, self._com_ground, self._com_line):
                handle.visible = show["com"]
            self._com.position = com
            self._com_ground.position = (com[0], com[1], 0.002)
            self._com_line.points = np.array([[com, [com[0], com[1], 0.0]]])
            poly = support_polygon(snap)
            self._support.visible = show["support"] and len(poly) >= 2
            if len(poly) >= 2:
                self._support.points = _ring_segments(poly, 0.003)
            segs, exceeded = [], False
            for kind, centre, radius in bound_circles(snap):
                if np.isfinite(radius):
                    segs.append(_ring_segments(centre + radius * _CIRCLE[:-1], 0.004))
                exceeded |= snap.bounds_active.get(kind, False)
            exceeded |= snap.bounds_active.get("lipm_force", False)
            exceeded &= not snap.fell  # after a fall the operator's bounds say nothing of the character
            self._bounds.visible = show["bounds"] and bool(segs)
            if segs:
                pts = np.concatenate(segs)
                self._bounds.points = pts
                self._bounds.colors = np.tile(np.array(_WARN if exceeded else _OK, dtype=np.uint8), (len(pts), 2, 1))
            offset = OPERATOR_BESIDE_M if self._overlay_mode.value == "beside" else np.zeros(3)
            bones = operator_overlay(snap, offset)
            self._operator.visible = show["operator"] and bones is not None
            if bones is not None:
                self._operator.points = bones
            if snap.character_stance is not self._label_stance:  # a label's text is fixed: make a new one
                self._stance_label.remove()
                self._stance_label = self.server.scene.add_label("/overlays/stance", snap.character_stance.name)
                self._label_stance = snap.character_stance
            self._stance_label.visible = show["stance"]
            self._stance_label.position = (com[0], com[1], 1.9)
            self._draw_balls(snap)
            self._follow_ground(com)
        now = time.perf_counter()
        if now - self._last_text >= TEXT_EVERY_S:
            self._last_text = now
            self._texts(snap)
        self._plots(snap)
        target = np.array([com[0], com[1]])
        if self._follow.value and np.linalg.norm(target - self._camera_target) > CAMERA_DEADBAND_M:
            self._camera_target = target
            for client in self.server.get_clients().values():
                _aim(client, com)

    def _follow_ground(self, com: np.ndarray) -> None:
        """The floor grid moves under the character in whole cells (its lines stay put on the ground) once the
        character is more than a quarter of the grid from its centre: the floor never ends under a long walk."""
        at = np.round(np.asarray(com[:2]) / GROUND_CELL_M) * GROUND_CELL_M
        if float(np.abs(at - self._ground_at).max()) > GROUND_SIZE_M / 4:
            self._ground_at = at
            self._ground.position = (float(at[0]), float(at[1]), 0.0)

    def _texts(self, snap: Snapshot) -> None:
        c = snap.com_world  # the COM marker's position, the same value
        status = (f"**t = {snap.time_s:.2f} s** · character {_STANCE_TEXT[snap.character_stance]} · "
                  f"operator {snap.operator_stance.name} · balls thrown: {len(snap.balls_world)} · "
                  f"COM ({c[0]:.3f}, {c[1]:.3f}, {c[2]:.3f}) m"
                  + (" · **fallen**" if snap.fell else ""))
        active = [k for k, v in snap.bounds_active.items() if v]
        warning = "⚠️ **operator exceeds the movement bounds: " + ", ".join(active) + "**" if active else ""
        if snap.fell:
            warning = "**the character fell** (Reset character stands it up)"
        if status != self._status.content:
            self._status.content = status
        if warning != self._warning.content:
            self._warning.content = warning

    def _draw_balls(self, snap: Snapshot) -> None:
        while len(self._balls) < len(snap.balls_world):
            self._balls.append(self.server.scene.add_icosphere(f"/balls/{len(self._balls)}", radius=0.11,
                                                               color=(245, 245, 245)))
        for h, p in zip(self._balls, snap.balls_world, strict=False):
            h.position = p

    def _plots(self, snap: Snapshot) -> None:
        self._history.append((snap.time_s, float(snap.com_world[0]), float(snap.com_world[1]),
                              float({Stance.LS: 0, Stance.DS: 1, Stance.RS: 2}[snap.character_stance])))
        while self._history and self._history[0][0] < snap.time_s - PLOT_WINDOW_S:
            self._history.popleft()
        now = time.perf_counter()
        if now - self._last_plot < PLOT_EVERY_S or len(self._history) < 2:
            return
        self._last_plot = now
        h = np.array(self._history)
        self._com_plot.data = (h[:, 0], h[:, 1], h[:, 2])
        self._stance_plot.data = (h[:, 0], h[:, 3])

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.server.stop()

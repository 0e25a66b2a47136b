"""Live operator stream in the VMC protocol (``vmc://HOST:PORT``): OSC over UDP, as VTuber and motion-capture
tools send it (Virtual Motion Capture, VSeeFace, XR Animator ...).

Messages read: ``/VMC/Ext/Root/Pos`` (name, position xyz, rotation xyzw of the root in the world) and
``/VMC/Ext/Bone/Pos`` (Unity humanoid bone name, local position xyz, local rotation xyzw relative to the parent
bone); ``/VMC/Ext/OK`` (model state) and ``/VMC/Ext/T`` (sender time [s]) close a frame, as does the end of a UDP
packet (an OSC bundle) in which a root and bones arrived, whatever the order of the messages in it; for senders
that spread a frame over several packets and send neither, a new root message after bones does. Unity axes are
left-handed, y up, z forward, metres; we convert to ours (x forward, y left, z up): ``p_ours = (p_z, -p_x, p_y)``,
and a quaternion's vector part ``(-q_z, q_x, -q_y)``. Bone rotations are taken relative to a normalised avatar's
rest pose (identity local rotations in its T-pose, as VRM avatars are); the rest pose's segment directions come
from the bones' local positions (sources/skeleton_tracks.py).

The socket listens on 127.0.0.1 unless another host is given. Each completed frame is stamped with its arrival
time (``extras["arrival_wall_s"]``, ``time.perf_counter``) so that the session can measure the latency from
arrival to the first control tick that uses it, and with its packet's receipt before parsing
(``extras["received_wall_s"]``): a frame closes with its own packet, so receipt to frame is the parsing alone.
Frames with NaN, missing bones or garbage arguments are rejected, counted and logged. :class:`VmcSender` sends
operator frames in the same protocol (for tests and for relaying).
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.base import QueuedLiveSource
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame
from stylesync.sources.skeleton_tracks import fill_canonical, rest_corrections

log = logging.getLogger("stylesync.sources")

# Unity humanoid bone -> parent bone (UpperChest is optional; bones under it fall back to Chest).
UNITY_PARENT: dict[str, str | None] = {
    "Hips": None, "Spine": "Hips", "Chest": "Spine", "UpperChest": "Chest", "Neck": "UpperChest", "Head": "Neck",
    "LeftUpperLeg": "Hips", "LeftLowerLeg": "LeftUpperLeg", "LeftFoot": "LeftLowerLeg", "LeftToes": "LeftFoot",
    "RightUpperLeg": "Hips", "RightLowerLeg": "RightUpperLeg", "RightFoot": "RightLowerLeg", "RightToes": "RightFoot",
    "LeftShoulder": "UpperChest", "LeftUpperArm": "LeftShoulder", "LeftLowerArm": "LeftUpperArm",
    "LeftHand": "LeftLowerArm", "RightShoulder": "UpperChest", "RightUpperArm": "RightShoulder",
    "RightLowerArm": "RightUpperArm", "RightHand": "RightLowerArm",
}
CANONICAL_BONE: dict[str, str] = {
    "PELVIS": "Hips", "SPINE_CHEST": "Chest", "NECK": "Neck", "HEAD": "Head",
    "HIP_LEFT": "LeftUpperLeg", "KNEE_LEFT": "LeftLowerLeg", "ANKLE_LEFT": "LeftFoot", "FOOT_LEFT": "LeftToes",
    "HIP_RIGHT": "RightUpperLeg", "KNEE_RIGHT": "RightLowerLeg", "ANKLE_RIGHT": "RightFoot", "FOOT_RIGHT": "RightToes",
    "SHOULDER_LEFT": "LeftUpperArm", "ELBOW_LEFT": "LeftLowerArm", "WRIST_LEFT": "LeftHand",
    "SHOULDER_RIGHT": "RightUpperArm", "ELBOW_RIGHT": "RightLowerArm", "WRIST_RIGHT": "RightHand",
}
REQUIRED_BONES = tuple(b for b in CANONICAL_BONE.values() if not b.endswith("Toes"))
DEFAULT_PORT = 39539  # the VMC protocol's usual performer -> marionette port


def ours_from_unity_pos(p) -> np.ndarray:
    x, y, z = (float(v) for v in p)
    return np.array([z, -x, y])


def unity_from_ours_pos(p) -> np.ndarray:
    x, y, z = (float(v) for v in p)
    return np.array([-y, z, x])


def ours_from_unity_quat(q_xyzw) -> np.ndarray:
    """Unity (x, y, z, w), left-handed, to our (w, x, y, z): the reflection flips the rotation's sense."""
    x, y, z, w = (float(v) for v in q_xyzw)
    return rot.normalize(np.array([w, -z, x, -y]))


def unity_from_ours_quat(q_wxyz) -> np.ndarray:
    w, x, y, z = (float(v) for v in q_wxyz)
    return np.array([y, -z, -x, w])


def _parent(bone: str, present: set[str]) -> str | None:
    par = UNITY_PARENT[bone]
    while par is not None and par not in present:
        par = UNITY_PARENT[par]
    return par


def frame_from_bones(t_s: float, root_pos: np.ndarray, root_q: np.ndarray,
                     bones: dict[str, tuple[np.ndarray, np.ndarray]],
                     q_rest: dict[str, np.ndarray] | None = None) -> tuple[OperatorFrame, dict[str, np.ndarray]]:
    """Forward kinematics of one VMC frame (our axes) into an operator frame; returns it and the rest corrections
    (computed from the bones' local positions when not given)."""
    present = set(bones)
    missing = [b for b in REQUIRED_BONES if b not in present]
    if missing:
        raise SourceError(f"VMC frame lacks bones {', '.join(missing)}")
    order = [b for b in UNITY_PARENT if b in present]
    world_p: dict[str, np.ndarray] = {}
    world_q: dict[str, np.ndarray] = {}
    rest_p: dict[str, np.ndarray] = {}
    for b in order:
        lp, lq = bones[b]
        par = _parent(b, present)
        if par is None:
            world_q[b] = rot.multiply(root_q, lq)
            world_p[b] = root_pos + rot.rotate(root_q, lp)
            rest_p[b] = lp.copy()
        else:
            world_q[b] = rot.multiply(world_q[par], lq)
            world_p[b] = world_p[par] + rot.rotate(world_q[par], lp)
            rest_p[b] = rest_p[par] + lp
    pos = np.zeros((1, N_JOINTS, 3))
    quat = np.tile(rot.IDENTITY_WXYZ, (1, N_JOINTS, 1))
    conf = np.zeros((1, N_JOINTS))
    rest_canon: dict[str, np.ndarray] = {}
    for canon, bone in CANONICAL_BONE.items():
        if bone in present:
            pos[0, JOINT_INDEX[canon]] = world_p[bone]
            rest_canon[canon] = rest_p[bone]
            conf[0, JOINT_INDEX[canon]] = 1.0
    for side, bone in (("LEFT", "LeftFoot"), ("RIGHT", "RightFoot")):
        if f"{side.capitalize()}Toes" not in present:  # no toes: a point 12 cm ahead of the ankle, on its sole
            k = JOINT_INDEX[f"FOOT_{side}"]
            pos[0, k] = world_p[bone] + rot.rotate(world_q[bone], np.array([0.12, 0.0, -0.06]))
            rest_canon[f"FOOT_{side}"] = rest_p[bone] + np.array([0.12, 0.0, -0.06])
            conf[0, k] = 1.0
    if q_rest is None:
        q_rest = rest_corrections(rest_canon)
    for canon, qr in q_rest.items():
        quat[0, JOINT_INDEX[canon]] = rot.multiply(world_q[CANONICAL_BONE[canon]], qr)
    fill_canonical(pos, quat, conf)
    return OperatorFrame(t_s, pos[0], quat[0], conf[0]), q_rest


class VmcSource(QueuedLiveSource):
    """Listens for VMC packets; ``poll`` returns the frames completed since the last call."""

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, max_queue: int = 256):
        try:
            from pythonosc import osc_packet
            from pythonosc.dispatcher import Dispatcher
            from pythonosc.osc_server import BlockingOSCUDPServer
        except ImportError:
            raise SourceError("the VMC source needs python-osc: pip install 'stylesync[live]'") from None
        super().__init__(max_queue)
        self.host = host
        self._root: tuple[np.ndarray, np.ndarray] | None = None
        self._bones: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._q_rest: dict[str, np.ndarray] | None = None
        self._t0 = time.perf_counter()
        self.frames_received = 0
        self._received_s = self._t0
        self._root_in_packet = False
        self._frame_spoiled = False
        self._parse = osc_packet.OscPacket
        # address -> (handler, smallest argument count)
        self._handlers = {"/VMC/Ext/Root/Pos": (self._on_root, 8), "/VMC/Ext/Bone/Pos": (self._on_bone, 8),
                          "/VMC/Ext/T": (self._on_time, 1), "/VMC/Ext/OK": (self._on_ok, 1)}
        source = self

        class _PacketDispatcher(Dispatcher):
            """Hands each UDP packet to the source whole (python-osc's own dispatch would sleep until a bundle's
            time tag and print tracebacks for garbage)."""

            def call_handlers_for_packet(self, data: bytes, client_address: tuple[str, int]) -> Any:
                source._on_packet(data)
                return []

        class _Server(BlockingOSCUDPServer):
            def verify_request(self, request: Any, client_address: Any) -> bool:
                return True  # every datagram reaches _on_packet, where what is not OSC is counted

            def handle_error(self, request: Any, client_address: Any) -> None:
                source._reject("handler error", "")  # counted, never a traceback on the terminal

        try:
            # One packet at a time, in arrival order: a frame is assembled from its packet's messages.
            self._server = _Server((host, port), _PacketDispatcher())
        except (OSError, OverflowError) as exc:
            raise SourceError(f"cannot listen for VMC on {host}:{port}: {getattr(exc, 'strerror', None) or exc}"
                              ) from None
        self.port = int(self._server.server_address[1])
        self._thread = threading.Thread(target=self._server.serve_forever, args=(0.1,), name="vmc-listener",
                                        daemon=True)
        self._thread.start()

    def _on_packet(self, data: bytes) -> None:
        """One UDP packet: its messages in order, then the end of the packet. Time tags are not waited on: a frame
        is timed on its arrival."""
        self._received_s = time.perf_counter()  # the packet's receipt, before it is parsed
        self._root_in_packet = False
        try:
            messages = [m.message for m in self._parse(data).messages]
        except Exception as exc:  # noqa: BLE001 - python-osc raises ParseError, struct, Unicode and index errors
            self._reject("malformed packet", f"{type(exc).__name__}: {exc}")
            return
        for msg in messages:
            entry = self._handlers.get(msg.address)
            if entry is None:
                if not msg.address.startswith("/VMC/"):  # other VMC messages (blend shapes, camera ...) are unused
                    self._reject("unknown address", msg.address[:80])
                continue
            handler, arity = entry
            args = list(msg.params)
            if len(args) < arity:
                self._reject("bad arity", f"{msg.address} with {len(args)} arguments")
                continue
            handler(*args)
        self._end_of_packet()

    def _end_of_packet(self) -> None:
        """A packet that carried a root and bones holds a whole frame (one bundle per frame)."""
        if self._root_in_packet and self._bones:
            self._complete(None)

    def _on_ok(self, *args: Any) -> None:
        self._complete(None)

    @staticmethod
    def _pose(args: list[Any]) -> tuple[np.ndarray, np.ndarray] | str:
        """Position and rotation of a Root/Bone message's arguments 1-7, or why they are not usable."""
        try:
            values = np.array([float(a) for a in args[1:8]])
        except (ValueError, TypeError, OverflowError):
            return "malformed message"
        if not np.all(np.isfinite(values)):
            return "non-finite values"
        if float(np.linalg.norm(values[3:7])) < 1e-6:
            return "zero quaternion"
        return ours_from_unity_pos(values[0:3]), ours_from_unity_quat(values[3:7])

    def _on_root(self, *args: Any) -> None:
        self._root_in_packet = True
        if self._bones:
            self._complete(None)
        pose = self._pose(list(args))
        if isinstance(pose, str):
            self._reject(pose, "/VMC/Ext/Root/Pos")
            self._root = None  # no frame until a usable root arrives
            return
        self._root = pose

    def _on_bone(self, *args: Any) -> None:
        pose = self._pose(list(args))
        if isinstance(pose, str):
            self._reject(pose, "/VMC/Ext/Bone/Pos")
            self._frame_spoiled = True  # the frame this bone belongs to is not passed on
            return
        name = str(args[0])
        if name in UNITY_PARENT:
            self._bones[name] = pose

    def _on_time(self, *args: Any) -> None:
        try:
            t: float | None = float(args[0])
        except (ValueError, TypeError, OverflowError):
            t = None
        self._complete(t if t is not None and np.isfinite(t) else None)

    def _complete(self, sender_time_s: float | None) -> None:
        arrival = time.perf_counter()
        bones, root, spoiled = self._bones, self._root, self._frame_spoiled
        self._bones, self._frame_spoiled = {}, False
        if root is None or not bones or spoiled:
            return
        try:
            frame, q_rest = frame_from_bones(arrival - self._t0, root[0], root[1], bones, self._q_rest)
        except SourceError as exc:
            self._reject("incomplete frame", str(exc))
            return
        self._q_rest = q_rest
        frame.extras["arrival_wall_s"] = arrival
        frame.extras["received_wall_s"] = self._received_s  # its (last) packet's receipt: arrival minus the parsing
        if sender_time_s is not None:
            frame.extras["sender_time_s"] = sender_time_s
        self.push(frame)
        self.frames_received += 1

    def _reject(self, why: str, detail: str) -> None:
        """Count a rejected packet, message or frame by reason; log the first of each reason with what it was."""
        self.rejected_frames += 1
        n = self.count_rejection(why)
        if n == 1:
            log.warning("vmc: rejected (%s)%s; later ones of this kind are counted in metrics.json", why,
                        f": {detail}" if detail else "")

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=1.0)


class VmcSender:
    """Sends operator frames as VMC packets (one OSC bundle per frame) to ``host:port``.

    The avatar is a normalised T-pose skeleton whose bones are measured on the first frame (offsets in each
    segment's canonical frame, limb lengths).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT):
        from pythonosc.udp_client import SimpleUDPClient

        self._client = SimpleUDPClient(host, port)
        self._rest_local: dict[str, np.ndarray] | None = None
        self._q_rest: dict[str, np.ndarray] | None = None

    def _rest_from(self, frame: OperatorFrame) -> None:
        """A T-pose avatar with the frame's bone lengths: legs down, arms out sideways, feet forward."""
        length = {b: float(np.linalg.norm(frame.pos(c) - frame.pos(p))) for c, p, b in (
            ("KNEE_LEFT", "HIP_LEFT", "LeftLowerLeg"), ("ANKLE_LEFT", "KNEE_LEFT", "LeftFoot"),
            ("ELBOW_LEFT", "SHOULDER_LEFT", "LeftLowerArm"), ("WRIST_LEFT", "ELBOW_LEFT", "LeftHand"))}
        def in_frame(seg: str, a: str, b: str) -> np.ndarray:
            """b - a in the canonical frame of ``seg`` (its rest pose is the identity)."""
            return rot.rotate(rot.conjugate(frame.quat(seg)), frame.pos(b) - frame.pos(a))

        chest = in_frame("PELVIS", "PELVIS", "SPINE_CHEST")
        local = {"Hips": np.zeros(3), "Spine": 0.5 * chest, "Chest": 0.5 * chest,
                 "Neck": in_frame("SPINE_CHEST", "SPINE_CHEST", "NECK"), "Head": in_frame("NECK", "NECK", "HEAD")}
        for side, s in (("Left", 1.0), ("Right", -1.0)):
            S = side.upper()
            shoulder = in_frame("SPINE_CHEST", "SPINE_CHEST", f"SHOULDER_{S}")
            local |= {f"{side}UpperLeg": in_frame("PELVIS", "PELVIS", f"HIP_{S}"),
                      f"{side}LowerLeg": np.array([0, 0, -length["LeftLowerLeg"]]),
                      f"{side}Foot": np.array([0, 0, -length["LeftFoot"]]),
                      f"{side}Toes": in_frame(f"ANKLE_{S}", f"ANKLE_{S}", f"FOOT_{S}"),
                      f"{side}Shoulder": 0.3 * shoulder, f"{side}UpperArm": 0.7 * shoulder,
                      f"{side}LowerArm": np.array([0, s * length["LeftLowerArm"], 0]),
                      f"{side}Hand": np.array([0, s * length["LeftHand"], 0])}
        self._rest_local = local
        rest_abs: dict[str, np.ndarray] = {}
        for b in local:
            par = _parent(b, set(local))
            rest_abs[b] = local[b] + (rest_abs[par] if par else 0.0)
        self._q_rest = rest_corrections({c: rest_abs[b] for c, b in CANONICAL_BONE.items()})

    def messages(self, frame: OperatorFrame, sender_time_s: float | None = None) -> list[tuple[str, list]]:
        """One frame's VMC messages (OSC address, arguments), in the order sent: the root, the bones, then
        ``/VMC/Ext/T`` (sender time) and ``/VMC/Ext/OK`` (model loaded), which close the frame."""
        if self._rest_local is None:
            self._rest_from(frame)
        assert self._rest_local is not None and self._q_rest is not None
        # World rotation of each bone relative to the T-pose: canonical ⊗ rest⁻¹.
        world_q = {CANONICAL_BONE[c]: rot.multiply(frame.quat(c), rot.conjugate(qr)) for c, qr in self._q_rest.items()}
        world_q["Spine"] = world_q["Hips"]
        world_q["Head"] = world_q["Neck"]
        for side in ("Left", "Right"):
            world_q[f"{side}Shoulder"] = world_q["Chest"]
            world_q[f"{side}Toes"] = world_q[f"{side}Foot"]
            world_q[f"{side}Hand"] = world_q[f"{side}LowerArm"]
        root_p = frame.pos("PELVIS")
        out: list[tuple[str, list]] = [("/VMC/Ext/Root/Pos", ["root", *unity_from_ours_pos(root_p).tolist(),
                                                               *unity_from_ours_quat(rot.IDENTITY_WXYZ).tolist()])]
        for b, lp in self._rest_local.items():
            par = _parent(b, set(self._rest_local))
            lq = world_q[b] if par is None else rot.multiply(rot.conjugate(world_q[par]), world_q[b])
            out.append(("/VMC/Ext/Bone/Pos", [b, *unity_from_ours_pos(lp).tolist(),
                                              *unity_from_ours_quat(lq).tolist()]))
        out.append(("/VMC/Ext/T", [float(frame.timestamp_s if sender_time_s is None else sender_time_s)]))
        out.append(("/VMC/Ext/OK", [1]))  # model loaded
        return out

    def send(self, frame: OperatorFrame, sender_time_s: float | None = None) -> None:
        """Send one frame as one OSC bundle."""
        self._client.send(osc_bundle(self.messages(frame, sender_time_s)))


def osc_bundle(messages: list[tuple[str, list]], timetag: float | None = None) -> Any:
    """One OSC bundle (python-osc's; ``.dgram`` its bytes) of (address, arguments) messages, time-tagged
    ``timetag`` (seconds since the epoch; None: immediately)."""
    from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
    from pythonosc.osc_message_builder import OscMessageBuilder

    bundle = OscBundleBuilder(IMMEDIATELY if timetag is None else timetag)  # type: ignore[arg-type]
    for addr, args in messages:
        m = OscMessageBuilder(address=addr)
        for a in args:
            m.add_arg(a)
        bundle.add_content(m.build())  # type: ignore[arg-type]
    return bundle.build()

"""BVH files as recorded operators (``bvh:PATH``), parsed with the maintained ``bvhio`` library.

Joints are matched by name to the canonical skeleton (sources/frame.py). Names are compared after dropping a
namespace prefix (``mixamorig:``), a Biped prefix (``Bip01``), case, spaces and punctuation; each canonical joint has
a list of candidates tried in order, which covers the MotionBuilder naming (CMU subject 2, Mixamo: ``LeftUpLeg``,
``LeftLeg``, ``LeftArm`` ...), the 3ds-Max naming (CMU subject 131: ``LeftHip``, ``LeftKnee``, ``LeftShoulder`` for
the upper arm ...) and Biped (``Bip01 L Thigh`` ...). A JSON object ``{"HIP_LEFT": "MyThigh", ...}`` given as
``joint_map`` overrides any entry.

Units: unless given, the scale to metres is the one of {m, cm, mm, inch, CMU (0.056444)} that makes the rest-pose
stature (ankle-to-head joint / 0.87) 1.0-2.3 m. Up axis: unless given, the file axis closest to head-minus-ankles
in the rest pose. A rest pose that does not stand upright (the legs not pointing away from the head: rigs with joint
frames along their bones lay every bone along x) tells neither: the up axis is then the one closest to the frames'
mean head-minus-ankles, the stature their tallest, and the segment orientations come from the joint positions
(segment_frames.py), as the rest pose cannot tell a segment's twist. The floor is placed by :func:`place_on_floor`.
"""

from __future__ import annotations

import logging
import re
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.base import read_json_file
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS
from stylesync.sources.limits import MAX_RECORDING_S, distance_problem, frame_interval_problem
from stylesync.sources.segment_frames import canonical_quats_from_positions
from stylesync.sources.skeleton_names import match_by_name
from stylesync.sources.skeleton_structure import match_by_structure
from stylesync.sources.skeleton_tracks import (
    REQUIRED_JOINTS,
    SEGMENT_DIRECTIONS,
    TrackPerformer,
    fill_canonical,
    place_on_floor,
    rest_corrections,
)

UNIT_SCALES_M: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254, "cmu": 0.056444}
STATURE_RANGE_M = (1.0, 2.3)
# Leading frames that blend from the skeleton's bind pose into the motion: converted files (the CMU Poser/DAZ
# conversions, some CMU originals) write the bind pose as frame 0, some with a few frames of blend, joints sweeping
# at 15-30 m/s relative to the pelvis, which no person did. Left out: leading frames, within the first
# BIND_BLEND_MAX_S, whose largest joint move to the next frame (relative to the pelvis) exceeds both
# BIND_BLEND_RATIO times the median move over the first BIND_BLEND_WINDOW_S and BIND_BLEND_MIN_MOVE_M.
BIND_BLEND_RATIO = 3.0
BIND_BLEND_WINDOW_S = 1.0
BIND_BLEND_MAX_S = 0.25
BIND_BLEND_MIN_MOVE_M = 0.01
UPRIGHT_REST_MIN_DEG = 120.0  # legs and spine at least this far apart: a rest pose standing upright
log = logging.getLogger("stylesync.sources")


def rest_stands_upright(pelvis: np.ndarray, ankles: list[np.ndarray], head: np.ndarray) -> bool:
    """Whether a skeleton's rest pose is a person standing: each leg (pelvis to its ankle) points away from the head
    (pelvis to head), at more than UPRIGHT_REST_MIN_DEG between them. Rigs whose joint frames have x along the bone
    lay every bone along x at rest, legs and spine alike, or one leg along +x and the other along -x (Bandai Namco's
    motion dataset): there the ankles' midpoint can lie below the pelvis although neither leg does."""
    spine = np.asarray(head) - pelvis
    cos_min = np.cos(np.radians(UPRIGHT_REST_MIN_DEG))
    for ankle in ankles:
        leg = np.asarray(ankle) - pelvis
        norms = float(np.linalg.norm(leg) * np.linalg.norm(spine))
        if norms <= 0 or float(leg @ spine) / norms >= cos_min:
            return False
    return True


def load_joint_map(path: str | Path) -> dict[str, str]:
    data = read_json_file(path, "joint map")
    if not isinstance(data, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in data.items()):
        raise SourceError(f"joint map {path}: expected a JSON object of canonical joint -> BVH joint name")
    unknown = sorted(set(data) - set(JOINT_INDEX))
    if unknown:
        raise SourceError(f"joint map {path}: unknown canonical joints {unknown}; expected names like HIP_LEFT")
    return data


def match_joints(names: list[str], joint_map: dict[str, str] | None = None, parent_index: list[int] | None = None,
                 rest: np.ndarray | None = None, end_sites: frozenset[int] = frozenset()
                 ) -> dict[str, tuple[str, str]]:
    """Canonical joint -> (BVH joint name, how it was matched), for the canonical joints found; raises, naming the
    missing segments, when a required one is missing.

    Names first (skeleton_names.py); when they leave a required joint unmatched and the tree is given
    (``parent_index``, ``rest`` positions), the joints are matched by structure (skeleton_structure.py). A joint
    map given by the user overrides either.
    """
    out = match_by_name(names)
    missing = [j for j in REQUIRED_JOINTS if j not in out]
    why_not_structure = ""
    if missing and parent_index is not None and rest is not None:
        try:
            out = match_by_structure(names, parent_index, rest, end_sites)
        except SourceError as exc:
            why_not_structure = f"; by structure: {exc}"
    for canon, bvh_name in (joint_map or {}).items():
        if bvh_name not in names:
            raise SourceError(f"joint map names '{bvh_name}' for {canon}, but the BVH has no such joint")
        out[canon] = (bvh_name, "joint map")
    missing = [j for j in REQUIRED_JOINTS if j not in out]
    if missing:
        raise SourceError(f"unknown skeleton: no BVH joint found for {', '.join(missing)}{why_not_structure} "
                          f"(joints in file: {', '.join(names[:40])}); give a joint map (JSON canonical -> BVH name)")
    return out


def _axes_matrix(up_axis: int, up_sign: float) -> np.ndarray:
    """File axes -> ours (z up), a proper rotation: ours z = file up, ours x, y = the next two file axes."""
    A = np.zeros((3, 3))
    A[2, up_axis] = up_sign
    A[0, (up_axis + 1) % 3] = up_sign
    A[1, (up_axis + 2) % 3] = 1.0
    return A


def _parse_line_or_fail_at_eof(file: Any, line_number: int) -> tuple[int, list[str], tuple[Any, int, int, str]]:
    """bvhio's line reader, except that the end of the file raises instead of looping forever (bvhio 1.5.4 spins
    on a truncated file) and that a joint name may hold spaces."""
    tokens: list[str] = []
    line = ""
    while not tokens:
        line_number += 1
        line = file.readline()
        if line == "":
            raise SyntaxError(f"unexpected end of file at line {line_number}")
        tokens = line.strip().split()
    if len(tokens) > 2 and tokens[0] in ("ROOT", "JOINT"):  # a name with spaces (3ds Max Biped: "Bip01 L Thigh")
        tokens = [tokens[0], " ".join(tokens[1:])]
    return line_number, tokens, (file, line_number, len(line) - len(line.lstrip()) + len(tokens[0]), line)


def _bvhio() -> Any:
    import bvhio
    import bvhio.lib.Parser as parser

    parser.parseLine = _parse_line_or_fail_at_eof  # type: ignore[assignment]
    return bvhio


def _declared_and_complete_frames(text: str) -> tuple[int, int, int, int] | None:
    """(frames declared, complete frame lines, the line index of "Frames:", that of the last complete frame line) of
    a BVH file's text; None when the text has no MOTION section, channel counts or frame count to compare (the parser
    then says what is wrong). A complete line holds as many values as the hierarchy's channels; counting stops at the
    first line that does not."""
    head, sep, motion = text.partition("MOTION")
    if not sep:
        return None
    first = head.count("\n")  # the MOTION line's index: motion.splitlines()[0] is the rest of that line
    try:
        n_channels = sum(int(m) for m in re.findall(r"\bCHANNELS\s+(\d+)", head))
        lines = motion.splitlines()
        k = next(i for i, ln in enumerate(lines) if ln.strip().lower().startswith("frames:"))
        declared = int(lines[k].split(":", 1)[1])
    except (StopIteration, ValueError):
        return None
    complete, last = 0, first + k + 1
    for i in range(k + 2, len(lines)):
        tokens = lines[i].split()
        if not tokens:
            continue
        if len(tokens) != n_channels:
            break
        complete, last = complete + 1, first + i
    return declared, complete, first + k, last


def _read_container(bvhio: Any, p: Path) -> Any:
    """bvhio's container of the file ``p``. A file cut short (fewer complete frame lines than its "Frames:" count
    says, the last one perhaps half written, as a capture that stopped) is read with the frames it has, and the
    shortfall logged: a recording's frames are not thrown away for the ones it lost. Frame lines beyond the count
    are logged and left out, as the parser reads the count."""
    text = p.read_text(errors="replace")
    counts = _declared_and_complete_frames(text)
    if counts is not None and counts[1] > counts[0]:
        log.warning("BVH file %s: %d frames declared, %d in the file; the %d declared are read", p, counts[0],
                    counts[1], counts[0])
    if counts is None or counts[1] >= counts[0] or counts[1] < 1:
        return bvhio.readAsBvh(str(p))
    declared, complete, frames_line, last = counts
    log.warning("BVH file %s: %d frames declared, %d complete in the file; the %d are read", p, declared, complete,
                complete)
    lines = text.splitlines()[:last + 1]
    lines[frames_line] = f"Frames: {complete}"
    with tempfile.TemporaryDirectory() as tmp:
        cut = Path(tmp) / p.name
        cut.write_text("\n".join(lines) + "\n")
        return bvhio.readAsBvh(str(cut))


def _depth_first(root: Any) -> list[tuple[Any, int]]:
    """(joint, parent index) in depth-first order, parents before children."""
    out: list[tuple[Any, int]] = []
    stack: list[tuple[Any, int]] = [(root, -1)]
    while stack:
        joint, parent = stack.pop()
        out.append((joint, parent))
        me = len(out) - 1
        stack.extend((child, me) for child in reversed(joint.Children))
    return out


def bind_blend_frames(pos: np.ndarray, frame_time_s: float) -> int:
    """How many leading frames of (T, 32, 3) canonical joint positions [m] blend from a bind pose (see
    BIND_BLEND_RATIO)."""
    n_window = min(len(pos), int(round(BIND_BLEND_WINDOW_S / frame_time_s)) + 1)
    if n_window < 4:
        return 0
    rel = pos[:n_window] - pos[:n_window, JOINT_INDEX["PELVIS"]][:, None]
    moves = np.linalg.norm(np.diff(rel, axis=0), axis=-1).max(axis=1)  # largest joint move per frame [m]
    limit = max(BIND_BLEND_RATIO * float(np.median(moves)), BIND_BLEND_MIN_MOVE_M)
    n_max = min(int(BIND_BLEND_MAX_S / frame_time_s), len(moves) - 1)
    n = 0
    while n < n_max and moves[n] > limit:
        n += 1
    return n


class BvhRecording:
    """A BVH file on the canonical skeleton; ``performer`` replays it."""

    @property
    def mapping(self) -> dict[str, str]:
        """Canonical joint -> the BVH joint it was matched to (``matches`` also says how)."""
        return {canon: name for canon, (name, _) in self.matches.items()}

    def __init__(self, path: str | Path, joint_map: dict[str, str] | None = None, scale_m: float | None = None,
                 up_axis: str | None = None):
        bvhio = _bvhio()
        p = Path(path)
        if not p.is_file():
            raise SourceError(f"BVH file not found: {p}")
        try:
            container = _read_container(bvhio, p)
            joints = _depth_first(container.Root)
            frame_time = float(container.FrameTime)
            n_frames = int(container.FrameCount)
        except Exception as exc:  # noqa: BLE001 - any failure of the third-party parser is a bad file
            raise SourceError(f"BVH file {p} could not be parsed: {type(exc).__name__}: {exc}".splitlines()[0]
                              ) from None
        if n_frames < 1 or not np.isfinite(frame_time) or frame_time <= 0:
            raise SourceError(f"BVH file {p}: needs at least one frame and a frame time > 0 s")
        if why := frame_interval_problem(frame_time):
            raise SourceError(f"BVH file {p}: Frame Time: {why}")
        if n_frames * frame_time > MAX_RECORDING_S:
            raise SourceError(f"BVH file {p}: {n_frames} frames of {frame_time:g} s last longer than "
                              f"{MAX_RECORDING_S:g} s")
        names = [j.Name for j, _ in joints]
        parent_index = [par for _, par in joints]
        if len(set(names)) != len(names):
            raise SourceError(f"BVH file {p}: joint names are not unique")
        try:
            local_pos = np.array([[[k.Position.x, k.Position.y, k.Position.z] for k in j.Keyframes]
                                  for j, _ in joints], dtype=float)  # (J, T, 3)
            local_q = np.array([[[k.Rotation.w, k.Rotation.x, k.Rotation.y, k.Rotation.z] for k in j.Keyframes]
                                for j, _ in joints], dtype=float)  # (J, T, 4)
            offsets = np.array([[j.Offset.x, j.Offset.y, j.Offset.z] for j, _ in joints], dtype=float)
        except (AttributeError, TypeError, ValueError) as exc:
            raise SourceError(f"BVH file {p}: malformed motion data ({exc})") from None
        if local_pos.shape[1] != n_frames or local_q.shape[1] != n_frames:
            raise SourceError(f"BVH file {p}: {n_frames} frames declared, motion data truncated")
        if not (np.all(np.isfinite(local_pos)) and np.all(np.isfinite(local_q)) and np.all(np.isfinite(offsets))):
            raise SourceError(f"BVH file {p} contains NaN or infinite values")
        # End sites as joints named "<joint>End": the toe of a foot without toe joints (Poser/DAZ).
        ends = [(f"{j.Name}End", i, np.array([j.EndSite.x, j.EndSite.y, j.EndSite.z], dtype=float))
                for i, (j, _) in enumerate(joints) if not j.Children and getattr(j, "EndSite", None) is not None]
        ends = [e for e in ends if e[0] not in names and np.all(np.isfinite(e[2])) and np.linalg.norm(e[2]) > 0]
        if ends:
            names = names + [e[0] for e in ends]
            parent_index = parent_index + [e[1] for e in ends]
            end_offsets = np.array([e[2] for e in ends])
            offsets = np.vstack([offsets, end_offsets])
            local_pos = np.concatenate([local_pos, np.repeat(end_offsets[:, None, :], n_frames, axis=1)])
            local_q = np.concatenate([local_q, np.tile(rot.IDENTITY_WXYZ, (len(ends), n_frames, 1))])
        # Rest pose (all rotations identity): cumulative offsets, file units and axes.
        rest = np.zeros((len(names), 3))
        for j, par in enumerate(parent_index):
            rest[j] = offsets[j] + (rest[par] if par >= 0 else 0.0)
        self.path = p
        self.joint_names = names
        n_joints = len(joints)
        self.matches = match_joints(names, joint_map, parent_index, rest,
                                    frozenset(range(n_joints, len(names))))
        idx = {canon: names.index(n) for canon, (n, _) in self.matches.items()}
        # A segment joint that coincides with the next one (CMU's Spine1 sits on its Neck) gives way to its parent.
        for seg, (distal, _) in SEGMENT_DIRECTIONS.items():
            while np.linalg.norm(rest[idx[distal]] - rest[idx[seg]]) < 1e-9 and parent_index[idx[seg]] >= 0:
                idx[seg] = parent_index[idx[seg]]
                self.matches[seg] = (names[idx[seg]], f"parent of {self.matches[seg][0]} (which sits on {distal})")
        # Forward kinematics over all frames, file axes and units.
        T = n_frames
        world_pos = np.zeros((len(names), T, 3))
        world_R = np.zeros((len(names), T, 3, 3))
        world_q = np.zeros((len(names), T, 4))
        for j, par in enumerate(parent_index):
            q_l = local_q[j] / np.linalg.norm(local_q[j], axis=1, keepdims=True)
            if par < 0:
                world_q[j] = q_l
                world_pos[j] = local_pos[j]
            else:
                world_q[j] = rot.batch_multiply(world_q[par], q_l)
                world_pos[j] = world_pos[par] + np.einsum("tij,tj->ti", world_R[par], local_pos[j])
            world_R[j] = rot.batch_matrix_from_quat(world_q[j])

        # The file's up axis and stature: from the rest pose when it stands upright, otherwise from the frames.
        rest_ankles = [rest[idx["ANKLE_LEFT"]], rest[idx["ANKLE_RIGHT"]]]
        up_vec = rest[idx["HEAD"]] - 0.5 * (rest_ankles[0] + rest_ankles[1])
        posed = not rest_stands_upright(rest[idx["PELVIS"]], rest_ankles, rest[idx["HEAD"]])
        up_t = world_pos[idx["HEAD"]] - 0.5 * (world_pos[idx["ANKLE_LEFT"]] + world_pos[idx["ANKLE_RIGHT"]])
        if posed:
            # Rigs whose bones lie along one axis at rest (joint frames with x along the bone): the pose at rest is
            # not a person standing, and only the frames say which way is up.
            up_vec = up_t.mean(axis=0)
            log.info("BVH file %s: the rest pose does not stand upright; up axis and stature from the frames", p)
        if up_axis is None:
            ax = int(np.argmax(np.abs(up_vec)))
            sign = float(np.sign(up_vec[ax]) or 1.0)
        else:
            if up_axis.lstrip("+-") not in ("x", "y", "z"):
                raise SourceError(f"up axis must be x, y or z (optionally signed), got '{up_axis}'")
            ax, sign = "xyz".index(up_axis.lstrip("+-")), (-1.0 if up_axis.startswith("-") else 1.0)
        # Ankle-to-head-joint height, ~87 % of stature: at rest, or the tallest over the frames.
        height = float(np.max(np.abs(up_t[:, ax]))) if posed else float(abs(up_vec[ax]))
        stature_units = height * 1.15
        if scale_m is None:
            fits = [s for s in UNIT_SCALES_M.values() if STATURE_RANGE_M[0] <= stature_units * s <= STATURE_RANGE_M[1]]
            if not fits:
                raise SourceError(f"BVH file {p}: stature {stature_units:.3g} file units fits none of the "
                                  f"units {sorted(UNIT_SCALES_M)}; give the scale to metres")
            scale_m = fits[0]
        if not (np.isfinite(scale_m) and scale_m > 0):
            raise SourceError(f"BVH scale to metres must be > 0, got {scale_m}")
        self.scale_m = float(scale_m)
        self.up_axis = ("+" if sign > 0 else "-") + "xyz"[ax]  # the file's up axis
        self.frame_time_s = frame_time
        self.stature_m = stature_units * self.scale_m
        A = _axes_matrix(ax, sign)
        q_axes = rot.quat_from_matrix(A)

        # Our axes and metres; canonical segment orientations q(t) = (A R_file(t) A^T) ⊗ q_rest. A rest pose that
        # does not stand cannot tell a segment's twist (rest_corrections takes a T- or A-pose's): the orientations
        # then come from the joint positions, as a position-only source's (segment_frames.py).
        rest_ours = {canon: A @ rest[i] * self.scale_m for canon, i in idx.items()}
        q_rest = {} if posed else rest_corrections(rest_ours)
        pos = np.zeros((T, N_JOINTS, 3))
        quat = np.tile(rot.IDENTITY_WXYZ, (T, N_JOINTS, 1))
        conf = np.zeros((T, N_JOINTS))
        qa = np.tile(q_axes, (T, 1))
        qa_inv = rot.batch_conjugate(qa)
        for canon, i in idx.items():
            k = JOINT_INDEX[canon]
            pos[:, k] = world_pos[i] @ A.T * self.scale_m
            conf[:, k] = 1.0
            if canon in q_rest:
                q_ours = rot.batch_multiply(rot.batch_multiply(qa, world_q[i]), qa_inv)
                quat[:, k] = rot.batch_multiply(q_ours, np.tile(q_rest[canon], (T, 1)))
        fill_canonical(pos, quat, conf)
        if posed:
            quat = canonical_quats_from_positions(pos)
        self.orientations_from_positions = posed
        n_bind = self.bind_frames_skipped = bind_blend_frames(pos, frame_time)
        if n_bind:
            log.info("BVH file %s: %d leading frame(s) blend from a bind pose; left out", p, n_bind)
            pos, quat, conf, T = pos[n_bind:], quat[n_bind:], conf[n_bind:], T - n_bind
        if why := distance_problem(pos, pos[0, JOINT_INDEX["PELVIS"]]):
            raise SourceError(f"BVH file {p}: {why}")
        place_on_floor(pos)
        self.performer = TrackPerformer(np.arange(T) * frame_time, pos, quat, conf, name=f"bvh:{p.name}")

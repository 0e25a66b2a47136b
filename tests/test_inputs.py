"""Operator inputs: BVH, Azure Kinect JSON, VMC, the source registry, body parameters (Sec. 4.1-4.2)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import wait_frames
from hypothesis import given, settings
from hypothesis import strategies as st

from stylesync import rotations as rot
from stylesync.cli import main as cli_main
from stylesync.errors import SourceError
from stylesync.processing.body_parameters import TABLE2_ROWS, com_from_joints, measure_operator
from stylesync.processing.point_cloud_volume import load_point_cloud, micro_cuboid_volume
from stylesync.sources.bvh import BvhRecording, load_joint_map
from stylesync.sources.frame import JOINT_INDEX
from stylesync.sources.human_model import HumanModel
from stylesync.sources.k4abt_json import K4abtRecording, write_k4abt_json
from stylesync.sources.registry import open_source
from stylesync.sources.skeleton_tracks import SEGMENT_DIRECTIONS

CMU = Path(__file__).resolve().parents[1].parent / "shared" / "mocap" / "cmu"
needs_cmu = pytest.mark.skipif(not CMU.is_dir(), reason="../shared/mocap/cmu (CMU BVH clips) is not present")

# A small BVH in centimetres, Y up, MotionBuilder names; the rest pose is a T-pose facing +z.
# (name, parent, offset, end site or None)
TINY_SKELETON = [
    ("Hips", None, (0, 0, 0), None),
    ("LeftUpLeg", "Hips", (10, 0, 0), None), ("LeftLeg", "LeftUpLeg", (0, -42, 0), None),
    ("LeftFoot", "LeftLeg", (0, -42, 0), None), ("LeftToeBase", "LeftFoot", (0, -5, 14), (0, 0, 4)),
    ("RightUpLeg", "Hips", (-10, 0, 0), None), ("RightLeg", "RightUpLeg", (0, -42, 0), None),
    ("RightFoot", "RightLeg", (0, -42, 0), None), ("RightToeBase", "RightFoot", (0, -5, 14), (0, 0, 4)),
    ("Spine", "Hips", (0, 25, 0), None), ("Neck", "Spine", (0, 25, 0), None), ("Head", "Neck", (0, 15, 0), (0, 10, 0)),
    ("LeftArm", "Spine", (18, 22, 0), None), ("LeftForeArm", "LeftArm", (28, 0, 0), None),
    ("LeftHand", "LeftForeArm", (25, 0, 0), (8, 0, 0)),
    ("RightArm", "Spine", (-18, 22, 0), None), ("RightForeArm", "RightArm", (-28, 0, 0), None),
    ("RightHand", "RightForeArm", (-25, 0, 0), (-8, 0, 0)),
]
_N_CHANNELS = 6 + 3 * (len(TINY_SKELETON) - 1)


def _hierarchy(names: dict[str, str]) -> str:
    def block(name: str, depth: int) -> list[str]:
        _, parent, off, end = next(j for j in TINY_SKELETON if j[0] == name)
        pad = "  " * depth
        head = "ROOT" if parent is None else "JOINT"
        chans = ("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" if parent is None
                 else "CHANNELS 3 Zrotation Xrotation Yrotation")
        lines = [f"{pad}{head} {names.get(name, name)}", f"{pad}{{", f"{pad}  OFFSET {off[0]} {off[1]} {off[2]}",
                 f"{pad}  {chans}"]
        for child in (j[0] for j in TINY_SKELETON if j[1] == name):
            lines += block(child, depth + 1)
        if end is not None:
            lines += [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {end[0]} {end[1]} {end[2]}", f"{pad}  }}"]
        return lines + [f"{pad}}}"]

    return "HIERARCHY\n" + "\n".join(block("Hips", 0)) + "\n"


def _write_tiny(tmp_path: Path, motion: list[list[float]] | None = None, names: dict[str, str] | None = None) -> Path:
    rows = motion or [[0, 95, 0] + [0.0] * (_N_CHANNELS - 3) for _ in range(3)]
    p = tmp_path / "tiny.bvh"
    p.write_text(_hierarchy(names or {}) + f"MOTION\nFrames: {len(rows)}\nFrame Time: 0.0333333\n"
                 + "\n".join(" ".join(f"{v:g}" for v in r) for r in rows) + "\n")
    return p


def test_tiny_bvh_units_axes_and_rest_pose(tmp_path):
    rec = BvhRecording(_write_tiny(tmp_path))
    assert rec.scale_m == pytest.approx(0.01)
    f = rec.performer.frame_at(0.0)
    # Y-up file -> z up; the hips 20 cm apart, the head above the pelvis.
    assert np.linalg.norm(f.pos("HIP_LEFT") - f.pos("HIP_RIGHT")) == pytest.approx(0.20, abs=1e-6)
    assert f.pos("HEAD")[2] - f.pos("PELVIS")[2] == pytest.approx(0.65, abs=1e-6)
    # floor: lowest ankle at Winter's ankle height, 0.079 of the 0.84 m hip-to-ankle length
    assert f.pos("ANKLE_LEFT")[2] == pytest.approx(0.039 / 0.491 * 0.84, abs=1e-3)
    # rest pose: every canonical segment hangs or stands as in the canonical rest pose, facing the file's +z
    yaw = rot.yaw_from_quat(f.quat("PELVIS"))
    facing = f.pos("FOOT_LEFT") - f.pos("ANKLE_LEFT")
    assert np.arctan2(facing[1], facing[0]) == pytest.approx(yaw, abs=1e-6)
    for seg, (distal, d0) in SEGMENT_DIRECTIONS.items():
        if seg.startswith("ANKLE"):
            continue
        d = f.pos(distal) - f.pos(seg)
        assert rot.rotate(f.quat(seg), np.array(d0)) @ d / np.linalg.norm(d) == pytest.approx(1.0, abs=1e-6), seg


def test_bvh_rotation_moves_the_segment(tmp_path):
    motion = [[0, 95, 0] + [0.0] * (_N_CHANNELS - 3) for _ in range(3)]
    motion[2][6 + 1] = -90.0  # LeftUpLeg Xrotation -90 deg: the thigh swings forward, towards the file's +z
    rec = BvhRecording(_write_tiny(tmp_path, motion))
    f0, f2 = rec.performer.frame_at(0.0), rec.performer.frame_at(2 * 0.0333333)
    knee_rel = f2.pos("KNEE_LEFT") - f2.pos("HIP_LEFT")
    assert knee_rel[2] == pytest.approx(0.0, abs=1e-6)  # horizontal thigh
    yaw = rot.yaw_from_quat(f0.quat("PELVIS"))
    assert knee_rel[:2] @ np.array([np.cos(yaw), np.sin(yaw)]) == pytest.approx(0.42, abs=1e-6)  # forward
    d = rot.rotate(f2.quat("HIP_LEFT"), np.array([0.0, 0.0, -1.0]))
    assert d @ knee_rel / 0.42 == pytest.approx(1.0, abs=1e-6)


def _bones_along_x(text: str) -> str:
    """The same BVH motion on joint frames with x along each joint's (first) bone, as rigs with joint frames along
    their bones write it: every bone lies along x at rest (legs and spine alike), and each frame's rotations turn it
    back. Joint j's frame becomes Q_j (x onto its bone); offsets of its children Q_j⁻¹ o; rotations Q_par⁻¹ R Q_j."""
    from scipy.spatial.transform import Rotation

    head, motion = text.split("MOTION", 1)
    lines = head.splitlines()
    joints: list[dict] = []
    stack: list[int] = []
    pending: dict = {}
    for i, ln in enumerate(lines):
        s = ln.strip()
        if s.startswith(("ROOT", "JOINT")):
            pending = {"parent": stack[-1] if stack else -1, "kids": [], "end": None}
            joints.append(pending)
        elif s.startswith("End Site"):
            pending = {"end_of": stack[-1]}
        elif s == "{":
            stack.append(len(joints) - 1 if "parent" in pending else stack[-1])
        elif s == "}":
            stack.pop()
        elif s.startswith("OFFSET"):
            v = np.array([float(x) for x in s.split()[1:4]])
            if "end_of" in pending:
                joints[pending["end_of"]]["end"] = (i, v)
            else:
                pending["line"], pending["off"] = i, v
        elif s.startswith("CHANNELS"):
            pending["chans"] = s.split()[2:]
    for j, jt in enumerate(joints):
        if jt["parent"] >= 0:
            joints[jt["parent"]]["kids"].append(j)
    q = []
    for jt in joints:
        bone = joints[jt["kids"][0]]["off"] if jt["kids"] else (jt["end"][1] if jt["end"] else np.zeros(3))
        length = float(np.linalg.norm(bone))
        if length < 1e-9:  # a joint on its child (CMU's hip joints): its frame stays
            q.append(Rotation.identity())
            continue
        x = np.array([1.0, 0.0, 0.0])
        axis, c = np.cross(x, bone / length), float(x @ bone) / length
        sin = float(np.linalg.norm(axis))
        q.append(Rotation.identity() if sin < 1e-9 and c > 0 else Rotation.from_rotvec(
            [0.0, 0.0, np.pi] if sin < 1e-9 else axis / sin * np.arctan2(sin, c)))

    def offset_line(i: int, v: np.ndarray) -> str:
        return lines[i][:len(lines[i]) - len(lines[i].lstrip())] + "OFFSET " + " ".join(f"{a:.6f}" for a in v)

    for j, jt in enumerate(joints):
        if jt["parent"] >= 0:
            lines[jt["line"]] = offset_line(jt["line"], q[jt["parent"]].inv().apply(jt["off"]))
        if jt["end"]:
            lines[jt["end"][0]] = offset_line(jt["end"][0], q[j].inv().apply(jt["end"][1]))
    header, *frames = motion.strip("\n").splitlines()[0:2], *motion.strip("\n").splitlines()[2:]
    out = []
    for fr in frames:
        values, k, row = [float(x) for x in fr.split()], 0, []
        for j, jt in enumerate(joints):
            names = jt["chans"]
            v = values[k:k + len(names)]
            k += len(names)
            rotation = [n for n in names if n.lower().endswith("rotation")]
            order = "".join(n[0].upper() for n in rotation)
            r = Rotation.from_euler(order, [x for n, x in zip(names, v, strict=True) if n.lower().endswith("rotation")],
                                    degrees=True)
            r = r * q[j] if jt["parent"] < 0 else q[jt["parent"]].inv() * r * q[j]
            angles = iter(r.as_euler(order, degrees=True))
            row += [next(angles) if n.lower().endswith("rotation") else x for n, x in zip(names, v, strict=True)]
        out.append(" ".join(f"{x:.6f}" for x in row))
    return "\n".join(lines) + "\nMOTION\n" + "\n".join(header + out) + "\n"


@needs_cmu
def test_a_bvh_whose_rest_pose_lays_every_bone_along_x_loads_as_the_same_motion(tmp_path, capsys):
    """Rigs with joint frames along their bones (x along the bone) lay every bone along x at rest: the rest pose says
    neither which way is up nor the file's units. The same CMU walk written that way loads with the same up axis,
    units and joint positions, its up axis and stature taken from the frames, its orientations from the joint
    positions (and `stylesync inspect` says so); before, its stature at rest (11.6 file units) fitted no unit and the
    file was refused."""
    original = BvhRecording(CMU / "02_01.bvh")
    path = tmp_path / "along_x.bvh"
    path.write_text(_bones_along_x((CMU / "02_01.bvh").read_text()))
    along_x = BvhRecording(path)
    assert (along_x.up_axis, along_x.scale_m) == (original.up_axis, original.scale_m)
    assert along_x.orientations_from_positions and not original.orientations_from_positions
    assert np.abs(along_x.performer.pos_world - original.performer.pos_world).max() < 1e-5
    assert cli_main(["inspect", str(path)]) == 0
    assert "from the frames (the rest pose does not stand" in capsys.readouterr().out
    hips = along_x.performer.pos_world[:, JOINT_INDEX["PELVIS"], 2]
    head = along_x.performer.pos_world[:, JOINT_INDEX["HEAD"], 2]
    assert np.all(head > hips + 0.3)  # standing: the head above the pelvis


# A rig mirrored from its left side (joint frames with x along each left bone and against each right one), in the
# naming and channel layout of Bandai Namco's motion dataset: a floor root, 6 channels on every joint, centimetres,
# y up. (joint, parent, offset [cm]); bones along +x on the left and the spine, -x on the right.
_MIRRORED_RIG = (
    ("joint_Root", None, (0, 0, 0)), ("Hips", "joint_Root", (0, 90, 0)), ("Spine", "Hips", (15, 0, 0)),
    ("Chest", "Spine", (9, 0, 0)), ("Neck", "Chest", (16, 0, 0)), ("Head", "Neck", (7, 0, 0)),
    ("Shoulder_L", "Chest", (13, 0, 5)), ("UpperArm_L", "Shoulder_L", (5, 0, 0)),
    ("LowerArm_L", "UpperArm_L", (24, 0, 0)), ("Hand_L", "LowerArm_L", (22, 0, 0)),
    ("Shoulder_R", "Chest", (13, 0, -5)), ("UpperArm_R", "Shoulder_R", (-5, 0, 0)),
    ("LowerArm_R", "UpperArm_R", (-24, 0, 0)), ("Hand_R", "LowerArm_R", (-22, 0, 0)),
    ("UpperLeg_L", "Hips", (-2, -7, 0)), ("LowerLeg_L", "UpperLeg_L", (39, 0, 0)), ("Foot_L", "LowerLeg_L", (41, 0, 0)),
    ("Toes_L", "Foot_L", (12, 0, 0)), ("UpperLeg_R", "Hips", (-2, 7, 0)), ("LowerLeg_R", "UpperLeg_R", (-39, 0, 0)),
    ("Foot_R", "LowerLeg_R", (-41, 0, 0)), ("Toes_R", "Foot_R", (-12, 0, 0)),
)


def _mirrored_rig_bvh(n_frames: int = 40) -> str:
    """A standing figure on :data:`_MIRRORED_RIG` that sways its pelvis sideways: the pelvis's frame turned +90° about
    z (its x, the spine, up; the right leg's -x down), the left thigh's a further 180° (its +x down), and the feet a
    quarter turn, so that the toes lie level (pointing outwards); every joint's position channels hold its offset."""
    kids: dict[str | None, list[str]] = {}
    for name, parent, _ in _MIRRORED_RIG:
        kids.setdefault(parent, []).append(name)
    offsets = {name: off for name, _, off in _MIRRORED_RIG}
    chans = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"

    def block(name: str, depth: int) -> list[str]:
        pad, head = "  " * depth, ("ROOT " if depth == 0 else "JOINT ") + name
        out = [pad + head, pad + "{", f"{pad}  OFFSET {' '.join(str(v) for v in offsets[name])}", f"{pad}  {chans}"]
        for kid in kids.get(name, []):
            out += block(kid, depth + 1)
        if name not in kids:
            out += [f"{pad}  End Site", pad + "  {", pad + "    OFFSET 0 0 0", pad + "  }"]
        return out + [pad + "}"]

    turn = {"Hips": (90, 0, 0), "UpperLeg_L": (180, 0, 0), "Foot_L": (90, 0, 0), "Foot_R": (-90, 0, 0)}
    rows = []
    for k in range(n_frames):
        row = []
        for name, _, off in _MIRRORED_RIG:
            pos = (5.0 * np.sin(0.2 * k), 90.0, 0.0) if name == "Hips" else off
            row += [*pos, *turn.get(name, (0, 0, 0))]
        rows.append(" ".join(f"{v:.4f}" for v in row))
    return "\n".join(["HIERARCHY", *block("joint_Root", 0), "MOTION", f"Frames: {n_frames}",
                      "Frame Time: 0.0333333", *rows]) + "\n"


def test_a_mirrored_rig_with_a_floor_root_loads_standing(tmp_path):
    """Its rest pose has the left leg along +x (with the spine) and the right along -x: the ankles' midpoint lies
    just behind the pelvis, opposite the head, as a standing person's would, although neither leg points away from
    the head. Each leg is now held against the spine: the rest pose does not stand, and the up axis and stature come
    from the frames. Before, the rest pose was taken as standing and the file refused ("joints ANKLE_LEFT and
    FOOT_LEFT coincide; cannot orient the segment")."""
    path = tmp_path / "mirrored.bvh"
    path.write_text(_mirrored_rig_bvh())
    rec = BvhRecording(path)
    assert (rec.up_axis, rec.scale_m) == ("+y", 0.01)
    assert rec.orientations_from_positions
    assert rec.mapping["ANKLE_LEFT"] == "Foot_L" and rec.mapping["FOOT_RIGHT"] == "Toes_R"
    pos = rec.performer.pos_world
    pelvis, head = pos[:, JOINT_INDEX["PELVIS"]], pos[:, JOINT_INDEX["HEAD"]]
    ankles = pos[:, [JOINT_INDEX["ANKLE_LEFT"], JOINT_INDEX["ANKLE_RIGHT"]]]
    assert np.all(head[:, 2] > pelvis[:, 2] + 0.4) and np.all(ankles[..., 2] < pelvis[:, None, 2] - 0.7)


def test_unknown_skeleton_and_custom_joint_map(tmp_path):
    p = _write_tiny(tmp_path, names={"LeftUpLeg": "Oberschenkel_L"})
    # A name not understood: the skeleton is matched by structure instead (skeleton_structure.py).
    by_structure = BvhRecording(p).matches
    assert by_structure["HIP_LEFT"] == ("Oberschenkel_L", "structure: left hip")
    assert by_structure["KNEE_RIGHT"][1] == "structure: right knee"
    jm = tmp_path / "map.json"
    jm.write_text(json.dumps({"HIP_LEFT": "Oberschenkel_L"}))
    rec = BvhRecording(p, joint_map=load_joint_map(jm))
    assert rec.mapping["HIP_LEFT"] == "Oberschenkel_L"
    jm.write_text(json.dumps({"HIPS": "x"}))
    with pytest.raises(SourceError, match="unknown canonical"):
        load_joint_map(jm)


@needs_cmu
@pytest.mark.parametrize("name, upper_arm", [("02_01", "LeftArm"), ("131_01", "LeftShoulder")])
def test_cmu_namings(name, upper_arm):
    rec = BvhRecording(CMU / f"{name}.bvh")
    assert rec.scale_m == pytest.approx(0.056444)
    assert rec.mapping["SHOULDER_LEFT"] == upper_arm
    f = rec.performer.frame_at(1.0)
    leg = np.linalg.norm(f.pos("HIP_LEFT") - f.pos("KNEE_LEFT")) + np.linalg.norm(f.pos("KNEE_LEFT")
                                                                                  - f.pos("ANKLE_LEFT"))
    assert 0.7 < leg < 0.95
    for seg in ("HIP_LEFT", "KNEE_RIGHT", "SHOULDER_LEFT", "ELBOW_RIGHT"):
        distal, d0 = SEGMENT_DIRECTIONS[seg]
        d = f.pos(distal) - f.pos(seg)
        assert rot.rotate(f.quat(seg), np.array(d0)) @ d / np.linalg.norm(d) > 0.999


@pytest.mark.parametrize("cut", ["whole lines", "mid-line"])
def test_a_bvh_cut_short_reads_the_frames_it_has(tmp_path, caplog, cut):
    motion = [[0, 95, 3.0 * k] + [0.0] * (_N_CHANNELS - 3) for k in range(12)]
    for k, row in enumerate(motion):
        row[6 + 1] = -4.0 * k  # the left thigh swings forward frame by frame
    whole = BvhRecording(_write_tiny(tmp_path, motion)).performer
    text = _write_tiny(tmp_path, motion).read_text()
    lines = text.splitlines()
    # 12 frames declared; 8 whole frame lines left, and with "mid-line" half of a ninth
    kept = lines[:len(lines) - 4] + ([lines[-4][:len(lines[-4]) // 2]] if cut == "mid-line" else [])
    p = tmp_path / "cut.bvh"
    p.write_text("\n".join(kept) + ("" if cut == "mid-line" else "\n"))
    with caplog.at_level("WARNING", logger="stylesync.sources"):
        part = BvhRecording(p).performer
    assert "12 frames declared, 8 complete" in caplog.text
    assert part.pos_world.shape[0] == 8
    np.testing.assert_allclose(part.pos_world, whole.pos_world[:8], atol=1e-9)


def test_a_bvh_with_no_complete_frame_fails(tmp_path):
    text = _write_tiny(tmp_path).read_text()
    p = tmp_path / "none.bvh"
    p.write_text(text[:text.index("Frame Time")] + "Frame Time: 0.0333333\n0 95\n")
    with pytest.raises(SourceError):
        BvhRecording(p)


@given(st.binary(max_size=400))
@settings(max_examples=40, deadline=None)
def test_bvh_parser_fails_cleanly_on_garbage(tmp_path_factory, data):
    p = tmp_path_factory.mktemp("b") / "x.bvh"
    p.write_bytes(data)
    with pytest.raises(SourceError):
        BvhRecording(p)


@given(st.integers(min_value=0, max_value=2000), st.sampled_from(["nan", "inf", "x", ""]))
@settings(max_examples=25, deadline=None)
def test_bvh_truncated_or_non_finite(tmp_path_factory, cut, bad):
    tmp = tmp_path_factory.mktemp("t")
    text = _write_tiny(tmp).read_text()
    p = tmp / "bad.bvh"
    p.write_text(text[: len(text) - 1 - cut % 200] if bad == "" else text.replace(" 95 ", f" {bad} ", 1))
    try:
        rec = BvhRecording(p)
    except SourceError:
        return
    # What parses must be finite.
    assert np.all(np.isfinite(rec.performer.pos_world))


@given(st.recursive(st.none() | st.booleans() | st.floats(allow_nan=True) | st.text(max_size=5),
                    lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=8), c, max_size=4),
                    max_leaves=30))
@settings(max_examples=60, deadline=None)
def test_k4a_json_fails_cleanly(tmp_path_factory, doc):
    p = tmp_path_factory.mktemp("k") / "x.json"
    p.write_text(json.dumps({"frames": doc}) if not isinstance(doc, dict) else json.dumps(doc))
    with pytest.raises(SourceError):
        K4abtRecording(p)


def test_k4a_json_rejects_bad_frames_and_keeps_good_ones(tmp_path):
    human = HumanModel()
    frames = [human.frame_from_pose(k / 30, np.array([0.01 * k, 0, 0.93]), {}) for k in range(10)]
    p = tmp_path / "rec.json"
    write_k4abt_json(frames, p)
    doc = json.loads(p.read_text())
    doc["frames"][3]["bodies"][0]["joint_positions"][5][0] = None  # garbage
    doc["frames"][5]["timestamp_usec"] = 0  # back in time
    doc["frames"][7]["bodies"] = []  # lost body
    del doc["stylesync_orientation"]  # orientations from positions, as for SDK files
    p.write_text(json.dumps(doc))
    rec = K4abtRecording(p)
    assert rec.rejected_frames == 3
    assert len(rec.performer.times_s) == 7


def test_k4a_json_round_trip_is_exact_to_the_micrometre(tmp_path):
    human = HumanModel()
    frames = [human.frame_from_pose(k / 30, np.array([0.02 * k, 0.1, 0.93]),
                                    {"HIP_LEFT": rot.quat_from_axis_angle(np.array([0, 1.0, 0]), -0.02 * k)})
              for k in range(20)]
    p = tmp_path / "rec.json"
    write_k4abt_json(frames, p)
    back = K4abtRecording(p).performer
    shift = back.pos_world[0, JOINT_INDEX["PELVIS"]] - frames[0].pos("PELVIS")
    assert np.allclose(shift[:2], [2.5, 0.0], atol=1e-5)  # the world origin is below the camera, 2.5 m behind
    for k, f in enumerate(frames):
        assert np.allclose(back.pos_world[k] - shift, f.joint_pos_world, atol=1e-5)
        assert np.allclose(np.abs(np.sum(back.quat_wxyz[k] * f.joint_quat_wxyz, axis=1)), 1.0, atol=1e-6)


@needs_cmu
def test_k4a_json_from_bvh_replays_to_the_same_character_motion(tmp_path):
    from stylesync.config import SessionConfig
    from stylesync.session import Session

    bvh = CMU / "02_01.bvh"
    rec = BvhRecording(bvh)
    k4a = tmp_path / "02_01.json"
    write_k4abt_json(rec.performer.frames(), k4a, camera_in_world_m=(0.0, 0.0, 0.0))
    roots, operator, times = [], [], []
    for spec in (f"bvh:{bvh}", f"k4a-json:{k4a}"):
        opened = open_source(spec, seed=3, duration_s=2.0)
        result = Session(SessionConfig(duration_s=2.0), opened.source).run()
        roots.append(np.stack([result.log.array("com_x"), result.log.array("com_y"), result.log.array("com_z")], 1))
        operator.append(np.array(result.log.columns["op_joints"]))
        times.append(result.log.array("t"))
    n = min(len(r) for r in roots)
    assert n > 150
    # The operator as the pipeline reads him, over the whole run (sensor noise is 5 mm): the file's round-off only.
    assert np.max(np.abs(operator[0][:n] - operator[1][:n])) < 0.005
    # The character over the first second. Later, the closed loop may turn that round-off (about 1e-6 m) into a
    # stance change a tick apart, and the runs part by centimetres, as two runs of one file do with noise seeds.
    first_s = times[0][:n] <= 1.0
    assert np.max(np.linalg.norm(roots[0][:n] - roots[1][:n], axis=1)[first_s]) < 0.005


def test_vmc_stream_from_another_process_drives_the_character(tmp_path):
    pytest.importorskip("pythonosc")
    from stylesync.config import SessionConfig
    from stylesync.session import Session
    from stylesync.sources.vmc import VmcSource

    source = VmcSource("127.0.0.1", 0)
    sender = subprocess.Popen([sys.executable, "-c", f"""
import time
from stylesync.sources.human_model import HumanModel
from stylesync.sources.vmc import VmcSender
import numpy as np
h = HumanModel(); s = VmcSender('127.0.0.1', {source.port}); t0 = time.perf_counter()
for k in range(int(5.0 * 60)):
    s.send(h.frame_from_pose(k / 60, np.array([0.3, -0.2, h.hip_height_m]), {{}}))
    time.sleep(max(0.0, t0 + (k + 1) / 60 - time.perf_counter()))
"""])
    try:
        result = Session(SessionConfig(duration_s=3.0, realtime=True), source).run()
    finally:
        sender.wait(timeout=30)
        source.close()
    assert not result.fell
    assert source.frames_received > 120 and source.rejected_frames == 0
    assert len(result.input_latency_ms) > 100
    # the character stands where the (scaled) operator stands: COM over the operator's x-y
    com = np.array([result.log.array("com_x")[-1], result.log.array("com_y")[-1]])
    assert np.linalg.norm(com - np.array([0.3, -0.2])) < 0.1


def test_registry_errors_are_one_line(tmp_path, capsys):
    with pytest.raises(SourceError, match="unknown source"):
        open_source("nonsense:1")
    with pytest.raises(SourceError, match="not found"):
        open_source(f"bvh:{tmp_path / 'missing.bvh'}")
    assert cli_main(["run", "--source", f"bvh:{tmp_path / 'missing.bvh'}", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("stylesync: error:") and "\n" not in err
    try:
        import mediapipe  # noqa: F401
    except ImportError:
        with pytest.raises(SourceError, match="pip install"):
            open_source("webcam:0")


def _box_points(a, b, c, n, rng):
    areas = np.array([b * c, b * c, a * c, a * c, a * b, a * b])
    k = (n * areas / areas.sum()).astype(int)
    u = rng.random
    return np.vstack([
        np.c_[np.zeros(k[0]), u(k[0]) * b, u(k[0]) * c], np.c_[np.full(k[1], a), u(k[1]) * b, u(k[1]) * c],
        np.c_[u(k[2]) * a, np.zeros(k[2]), u(k[2]) * c], np.c_[u(k[3]) * a, np.full(k[3], b), u(k[3]) * c],
        np.c_[u(k[4]) * a, u(k[4]) * b, np.zeros(k[4])], np.c_[u(k[5]) * a, u(k[5]) * b, np.full(k[5], c)]])


def test_micro_cuboid_volume_of_box_and_cylinder_within_2_percent():
    rng = np.random.default_rng(0)
    box = _box_points(0.3, 0.2, 0.5, 600_000, rng)
    assert micro_cuboid_volume(box) == pytest.approx(0.3 * 0.2 * 0.5, rel=0.02)
    n = 500_000
    th, z = rng.random(n) * 2 * np.pi, rng.random(n) * 0.5
    cyl = np.c_[0.1 * np.cos(th), 0.1 * np.sin(th), z]
    assert micro_cuboid_volume(cyl) == pytest.approx(np.pi * 0.1**2 * 0.5, rel=0.02)


def test_point_cloud_loader_rejects_bad_files(tmp_path):
    p = tmp_path / "c.npy"
    np.save(p, np.array([[0, 0, np.nan]] * 5))
    with pytest.raises(SourceError, match="NaN"):
        load_point_cloud(p)
    (tmp_path / "c.ply").write_text("ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n")
    with pytest.raises(SourceError):
        load_point_cloud(tmp_path / "c.ply")


def test_anthropometric_fallback_reproduces_its_table_and_com_lies_between_the_feet():
    human = HumanModel(1.75, 75.8)
    f = human.frame_from_pose(0.0, np.array([0.0, 0.0, human.hip_height_m]), {})
    table = measure_operator([f], 75.8)
    per_side = {r[0]: r[3] for r in TABLE2_ROWS}
    total = sum(v * (2 if "{S}" in r[1] else 1) for r, v in zip(TABLE2_ROWS, per_side.values(), strict=True))
    assert total == pytest.approx(1.0, abs=0.002)  # Winter's fractions sum to one
    for name, frac in per_side.items():
        assert table.mass_kg[name] == pytest.approx(75.8 * frac / total, rel=1e-9)
    assert table.length_m["upper_leg"] == pytest.approx(human.thigh_m, rel=1e-6)
    com = com_from_joints({n: f.pos(n) for n in JOINT_INDEX})
    yl, yr = f.pos("ANKLE_LEFT")[1], f.pos("ANKLE_RIGHT")[1]
    assert min(yl, yr) < com[1] < max(yl, yr) and abs(com[1]) < 1e-9
    heel_x, toe_x = f.pos("ANKLE_LEFT")[0] - 0.05, f.pos("FOOT_LEFT")[0]
    assert heel_x < com[0] < toe_x


def test_measure_cli_prints_the_link_table(capsys):
    assert cli_main(["measure", "--source", "deepmimic:walk", "--mass", "70"]) == 0
    out = capsys.readouterr().out
    assert "upper_leg" in out and "70.0 kg" in out


def _vmc_bundle(messages):
    from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
    from pythonosc.osc_message_builder import OscMessageBuilder

    bundle = OscBundleBuilder(IMMEDIATELY)
    for addr, args in messages:
        m = OscMessageBuilder(address=addr)
        for a in args:
            m.add_arg(a)
        bundle.add_content(m.build())
    return bundle.build()


def test_vmc_frames_close_with_their_own_packet_whatever_the_message_order():
    """A frame is complete when its packet has arrived: with /VMC/Ext/T and /VMC/Ext/OK after the bones, before
    them (a sender that stamps the frame first), or absent; a sender that spreads a frame over several packets and
    sends neither closes it with its next root."""
    pytest.importorskip("pythonosc")
    from pythonosc.udp_client import SimpleUDPClient

    from stylesync.sources.human_model import HumanModel
    from stylesync.sources.vmc import VmcSender, VmcSource

    source = VmcSource("127.0.0.1", 0)
    client = SimpleUDPClient("127.0.0.1", source.port)
    h = HumanModel()
    builder = VmcSender("127.0.0.1", 9)  # builds the messages; nothing is sent to port 9
    try:
        msgs = builder.messages(h.frame_from_pose(0.0, np.array([0.0, 0.0, h.hip_height_m]), {}))
        marks = [m for m in msgs if m[0] in ("/VMC/Ext/T", "/VMC/Ext/OK")]
        body = [m for m in msgs if m not in marks]
        for k, order in enumerate((body + marks, marks + body, body), start=1):
            client.send(_vmc_bundle(order))
            assert wait_frames(source, k) == k  # no next packet needed
        # Spread over packets, no T / OK: the next root closes the frame.
        for addr, args in body:
            client.send_message(addr, args)
        assert wait_frames(source, 4, timeout_s=0.2) == 3
        client.send_message(*body[0])
        assert wait_frames(source, 4) == 4
        assert source.rejected_frames == 0
    finally:
        source.close()


def test_vmc_from_vmcp_own_sender_arrives_frame_by_frame():
    """A third-party VMC sender (vmcp, PyPI, over osc4py3: ``pip install 'vmcp[osc4py3]'``, an optional test
    dependency) sending bundles in its documented order (root, bones, /VMC/Ext/OK, /VMC/Ext/T): every frame is
    received before the next is sent; then 30 s at 60 Hz lose no frame."""
    pytest.importorskip("pythonosc")
    pytest.importorskip("vmcp")
    pytest.importorskip("osc4py3")
    import time

    from vmcp.osc import OSC
    from vmcp.osc.backend.osc4py3 import as_comthreads as backend
    from vmcp.osc.typing import Message

    from stylesync.sources.human_model import HumanModel
    from stylesync.sources.vmc import VmcSender, VmcSource

    def typetags(args):
        return "," + "".join("s" if isinstance(a, str) else "i" if isinstance(a, int) else "f" for a in args)

    source = VmcSource("127.0.0.1", 0)
    h = HumanModel()
    builder = VmcSender("127.0.0.1", 9)
    osc = OSC(backend)
    try:
        with osc.open():
            sender = osc.create_sender("127.0.0.1", source.port, "stylesync-test").open()
            for k in range(20):
                msgs = builder.messages(h.frame_from_pose(k / 60, np.array([0.3, -0.2, h.hip_height_m]), {}))
                ok = [m for m in msgs if m[0] == "/VMC/Ext/OK"]
                t = [m for m in msgs if m[0] == "/VMC/Ext/T"]
                body = [m for m in msgs if m[0] not in ("/VMC/Ext/OK", "/VMC/Ext/T")]
                sender.send(tuple(Message(a, typetags(v), tuple(v)) for a, v in body + ok + t))
                t0 = time.perf_counter()
                while source.frames_received < k + 1 and time.perf_counter() - t0 < 1.0:
                    osc.run()
                    time.sleep(0.0005)
                assert source.frames_received == k + 1
            assert source.rejected_frames == 0
            frame = source.poll(1e9)[-1]
            assert np.linalg.norm(frame.pos("PELVIS")[:2] - np.array([0.3, -0.2])) < 0.01
            # Then at 60 Hz for 30 s (osc4py3 starts once per process, so in the same session): every frame
            # arrives, none is rejected, and each exists (median) within half a frame period of its packet's
            # receipt: it closes with its own packet, not when the next one comes (16.7 ms later at 60 Hz). Measured
            # with both cores loaded by other runs: a median of 2.5 ms.
            n = 30 * 60
            steady = VmcSource("127.0.0.1", 0, max_queue=n)
            bundles = []
            for k in range(n):
                msgs = builder.messages(h.frame_from_pose(k / 60, np.array([0.01 * k, 0.0, h.hip_height_m]), {}))
                tail = [m for m in msgs if m[0] == "/VMC/Ext/OK"] + [m for m in msgs if m[0] == "/VMC/Ext/T"]
                body = [m for m in msgs if m[0] not in ("/VMC/Ext/OK", "/VMC/Ext/T")]
                bundles.append(tuple(Message(a, typetags(v), tuple(v)) for a, v in body + tail))
            try:
                to_steady = osc.create_sender("127.0.0.1", steady.port, "stylesync-test-60hz").open()
                t0 = time.perf_counter()
                for k, bundle in enumerate(bundles):
                    while time.perf_counter() < t0 + k / 60:
                        time.sleep(0.0005)
                    to_steady.send(bundle)
                    osc.run()
                deadline = time.perf_counter() + 2.0
                while steady.frames_received < n and time.perf_counter() < deadline:
                    osc.run()
                    time.sleep(0.001)
                assert steady.frames_received == n and steady.rejected_frames == 0
                frames = steady.poll(1e9)
                xs = np.array([f.pos("PELVIS")[0] for f in frames])
                assert len(frames) == n and np.allclose(np.diff(xs), 0.01, atol=1e-3)  # in order, each its own
                to_frame_ms = [1e3 * (f.extras["arrival_wall_s"] - f.extras["received_wall_s"]) for f in frames]
                assert float(np.median(to_frame_ms)) < 0.5 * 1e3 / 60
            finally:
                steady.close()
    finally:
        source.close()


@needs_cmu
def test_a_run_names_the_sensor_its_frames_passed_through():
    opened = open_source(f"bvh:{CMU / '02_01.bvh'}", seed=0, duration_s=1.0)
    assert opened.sensor == "kinect"
    assert open_source(f"bvh:{CMU / '02_01.bvh'}", sensor="none", duration_s=1.0).sensor == "none"
    pytest.importorskip("pythonosc")
    live = open_source("vmc://127.0.0.1:0")
    try:
        assert live.sensor == "live"
    finally:
        live.source.close()


def _walk_frames(seconds):
    from stylesync.config import SessionConfig
    from stylesync.sources.builtin_operator import builtin_operator

    cfg = SessionConfig(duration_s=seconds)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, seconds + 1.0, 0)
    return cfg, source.poll(1e9)


def test_a_recording_whose_first_frames_lost_joints_starts_at_its_first_whole_frame():
    """A lost knee (no confidence) in the first five frames, or NaN there (those frames rejected): the character
    starts from the first frame with every joint tracked, not from garbage, and the run goes on."""
    from stylesync.session import Session
    from stylesync.sources.base import RecordedSource
    from stylesync.sources.frame import JOINT_INDEX

    for lost in (0.0, np.nan):
        cfg, frames = _walk_frames(1.0)
        for f in frames[:5]:
            f.confidence[JOINT_INDEX["KNEE_LEFT"]] = 0.0
            f.joint_pos_world[JOINT_INDEX["KNEE_LEFT"]] = lost
        result = Session(cfg, RecordedSource(frames)).run()
        assert not result.fell and result.sim_duration_s == pytest.approx(1.0, abs=0.01)


def test_a_recording_with_no_whole_frame_ends_with_one_clear_line(tmp_path, capsys):
    from stylesync.session import Session
    from stylesync.sources.base import RecordedSource
    from stylesync.sources.frame import JOINT_INDEX

    cfg, frames = _walk_frames(1.0)
    for f in frames:
        f.confidence[JOINT_INDEX["ANKLE_RIGHT"]] = 0.0
    with pytest.raises(SourceError, match="no frame with every joint tracked"):
        Session(cfg, RecordedSource(frames)).run()


def test_a_live_source_whose_frames_all_lost_joints_ends_with_one_clear_line(monkeypatch):
    from stylesync import session as session_module
    from stylesync.session import Session
    from stylesync.sources.base import QueuedLiveSource
    from stylesync.sources.frame import JOINT_INDEX

    cfg, frames = _walk_frames(1.0)
    for f in frames:
        f.confidence[JOINT_INDEX["HIP_LEFT"]] = 0.0
    live = QueuedLiveSource(256)
    for f in frames:
        live.push(f)
    monkeypatch.setattr(session_module, "FIRST_FRAME_TIMEOUT_S", 0.3)
    with pytest.raises(SourceError, match="no operator frame with every joint tracked arrived within"):
        Session(cfg, live).run()


@pytest.mark.parametrize("frame_time", ["1e-9", "1e300", "5"])
def test_bvh_frame_time_outside_a_capture_rate_is_one_clear_error(tmp_path, frame_time):
    p = _write_tiny(tmp_path)
    p.write_text(p.read_text().replace("Frame Time: 0.0333333", f"Frame Time: {frame_time}"))
    with pytest.raises(SourceError, match=r"Frame Time: frame interval .* outside \[0.0001, 1\] s"):
        BvhRecording(p)


def test_bvh_positions_beyond_a_kilometre_are_refused(tmp_path):
    motion = [[0, 95, 0] + [0.0] * (_N_CHANNELS - 3) for _ in range(3)]
    motion[2][0] = 1e9  # root 10 000 km away (cm)
    with pytest.raises(SourceError, match="m from where the recording starts"):
        BvhRecording(_write_tiny(tmp_path, motion))


def test_deepmimic_frame_durations_outside_a_capture_rate_are_refused(tmp_path):
    import pybullet_data

    from stylesync.sources.deepmimic_clip import DeepMimicClip

    src = json.loads((Path(pybullet_data.getDataPath()) / "data/motions/humanoid3d_walk.txt").read_text())
    src["Frames"][2][0] = 1e-300
    p = tmp_path / "clip.txt"
    p.write_text(json.dumps(src))
    with pytest.raises(SourceError, match="frame 2: frame interval"):
        DeepMimicClip.load(p)


def test_k4a_json_frames_far_in_time_or_space_are_rejected_and_counted(tmp_path):
    human = HumanModel()
    frames = [human.frame_from_pose(k / 30, np.array([0.01 * k, 0, 0.93]), {}) for k in range(10)]
    p = tmp_path / "rec.json"
    write_k4abt_json(frames, p)
    doc = json.loads(p.read_text())
    doc["frames"][4]["timestamp_usec"] = 10**30  # 3e16 years later
    doc["frames"][6]["bodies"][0]["joint_positions"][0][0] = 1e12  # a million km away (mm)
    p.write_text(json.dumps(doc))
    rec = K4abtRecording(p)
    assert rec.rejected_frames == 2
    assert rec.performer.times_s[-1] < 1.0


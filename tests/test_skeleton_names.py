"""Skeleton naming conventions: names read as (side, segment), and renamed variants of one CMU clip give the same
operator joints as the original."""

import re
from pathlib import Path

import numpy as np
import pytest

from stylesync.cli import main as cli_main
from stylesync.errors import SourceError
from stylesync.sources.bvh import BvhRecording, match_joints
from stylesync.sources.frame import JOINT_INDEX
from stylesync.sources.skeleton_names import ParsedName, match_by_name, parse_name

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
needs_cmu = pytest.mark.skipif(not (MOCAP / "cmu").is_dir(),
                               reason="../shared/mocap/cmu (CMU BVH clips) is not present")
needs_cmu_dev = pytest.mark.skipif(not (MOCAP / "cmu-dev").is_dir(),
                                   reason="../shared/mocap/cmu-dev (Poser/DAZ CMU clips) is not present")


@pytest.mark.parametrize("name, side, word, helper", [
    ("mixamorig:LeftUpLeg", "left", "upleg", False),
    ("UpperLeg_L", "left", "upperleg", False),
    ("LowerLeg_R", "right", "lowerleg", False),
    ("Bip01 L Thigh", "left", "thigh", False),
    ("thigh.L", "left", "thigh", False),
    ("DEF-shin.R", "right", "shin", False),
    ("lThighBend", "left", "thigh", False),
    ("lThighTwist", "left", "thightwist", True),
    ("rShldr", "right", "shldr", False),
    ("CC_Base_L_Calf", "left", "calf", False),
    ("J_Bip_C_Hips", None, "hips", False),
    ("J_Bip_L_UpperArm", "left", "upperarm", False),
    ("Armature|Spine2", None, "spine2", False),
    ("lowerback", None, "lowerback", False),
    ("lhand", "left", "hand", False),
    ("rightforearm", "right", "forearm", False),
    ("hip", None, "hip", False),
    ("LHipJoint", "left", "hipjoint", False),
    ("lFootEnd", "left", "footend", False),
    ("L_Ankle", "left", "ankle", False),
    ("left_foot", "left", "foot", False),
    ("LUArm", "left", "uarm", False),
    ("RFArm", "right", "farm", False),
    ("foot.LEnd", "left", "footend", False),  # the loader's end-site suffix after a side suffix (Blender)
    ("forearm.REnd", "right", "forearmend", False),
    ("LeftFootEnd", "left", "footend", False),
    ("spine.001", None, "spine1", False),  # numbered bones: Blender's .001, Unreal's spine_03
    ("spine_03", None, "spine3", False),
])
def test_parse_name(name, side, word, helper):
    assert parse_name(name) == ParsedName(side, word, helper)


def test_first_ranked_synonym_wins_and_helpers_are_skipped():
    # MotionBuilder: LeftShoulder is the clavicle, LeftArm the upper arm.
    m = match_by_name(["Hips", "LeftShoulder", "LeftArm"])
    assert m["SHOULDER_LEFT"][0] == "LeftArm" and m["PELVIS"][0] == "Hips"
    # 3ds Max (CMU 131): LeftShoulder is the upper arm.
    assert match_by_name(["Hips", "LeftCollar", "LeftShoulder"])["SHOULDER_LEFT"][0] == "LeftShoulder"
    m = match_by_name(["lThighBend", "lThighTwist", "lShin"])
    assert m["HIP_LEFT"][0] == "lThighBend" and m["KNEE_LEFT"][0] == "lShin"
    # SMPL: the ankle is L_Ankle and its child L_Foot the toe; MotionBuilder's LeftFoot is the ankle.
    m = match_by_name(["Pelvis", "L_Hip", "L_Knee", "L_Ankle", "L_Foot"])
    assert m["ANKLE_LEFT"][0] == "L_Ankle" and m["FOOT_LEFT"][0] == "L_Foot"
    # A file joint stands for one canonical joint: a foot joint taken as the ankle is not the toe as well.
    m = match_by_name(["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftFootEnd"])
    assert m["ANKLE_LEFT"][0] == "LeftFoot" and m["FOOT_LEFT"][0] == "LeftFootEnd"
    # OptiTrack Motive: LShoulder is the clavicle, LUArm the upper arm, LFArm the forearm.
    m = match_by_name(["Hip", "LShoulder", "LUArm", "LFArm", "LHand"])
    assert m["SHOULDER_LEFT"][0] == "LUArm" and m["ELBOW_LEFT"][0] == "LFArm"


# Renamings of CMU 02_01's MotionBuilder names into the conventions users bring (toe, clavicle and neck joints kept):
# SMPL/AMASS exports (an ankle joint and a foot joint below it), Xsens MVN, OptiTrack Motive among them.
_SEGMENTS = {  # MotionBuilder name (side "Left"/"Right" or none) -> convention -> name pattern ({L}/{Left}: side)
    "Hips": {"unity": "Hips", "poser": "hip", "blender": "pelvis", "biped": "Bip01 Pelvis", "vrm": "J_Bip_C_Hips",
             "smpl": "Pelvis", "smplx": "pelvis", "xsens": "Hips", "motive": "Hip", "asf": "root", "unreal": "pelvis"},
    "UpLeg": {"unity": "UpperLeg_{L}", "poser": "{l}ThighBend", "blender": "thigh.{L}", "biped": "Bip01 {L} Thigh",
              "vrm": "J_Bip_{L}_UpperLeg",
              "smpl": "{L}_Hip", "smplx": "{left}_hip", "xsens": "{Left}Hip", "motive": "{L}Thigh", "asf": "{l}femur",
              "unreal": "thigh_{l}"},
    "Leg": {"unity": "LowerLeg_{L}", "poser": "{l}Shin", "blender": "DEF-shin.{L}", "biped": "Bip01 {L} Calf",
            "vrm": "J_Bip_{L}_LowerLeg",
            "smpl": "{L}_Knee", "smplx": "{left}_knee", "xsens": "{Left}Knee", "motive": "{L}Shin", "asf": "{l}tibia",
            "unreal": "calf_{l}"},
    "Foot": {"unity": "Foot_{L}", "poser": "{l}Foot", "blender": "foot.{L}", "biped": "Bip01 {L} Foot",
             "vrm": "J_Bip_{L}_Foot",
             "smpl": "{L}_Ankle", "smplx": "{left}_ankle", "xsens": "{Left}Ankle", "motive": "{L}Foot",
             "asf": "{l}foot", "unreal": "foot_{l}"},
    "ToeBase": {"unity": "Toes_{L}", "poser": "{l}Toe", "blender": "toe.{L}", "biped": "Bip01 {L} Toe0",
                "vrm": "J_Bip_{L}_ToeBase",
                "smpl": "{L}_Foot", "smplx": "{left}_foot", "xsens": "{Left}Toe", "motive": "{L}Toe", "asf": "{l}toes",
                "unreal": "ball_{l}"},
    "Arm": {"unity": "UpperArm_{L}", "poser": "{l}ShldrBend", "blender": "upper_arm.{L}",
            "biped": "Bip01 {L} UpperArm", "vrm": "J_Bip_{L}_UpperArm",
            "smpl": "{L}_Shoulder", "smplx": "{left}_shoulder", "xsens": "{Left}Shoulder", "motive": "{L}UArm",
            "asf": "{l}humerus", "unreal": "upperarm_{l}"},
    "ForeArm": {"unity": "LowerArm_{L}", "poser": "{l}ForearmBend", "blender": "forearm.{L}",
                "biped": "Bip01 {L} Forearm", "vrm": "J_Bip_{L}_LowerArm",
                "smpl": "{L}_Elbow", "smplx": "{left}_elbow", "xsens": "{Left}Elbow", "motive": "{L}FArm",
                "asf": "{l}radius", "unreal": "lowerarm_{l}"},
    "Hand": {"unity": "Hand_{L}", "poser": "{l}Hand", "blender": "hand.{L}", "biped": "Bip01 {L} Hand",
             "vrm": "J_Bip_{L}_Hand",
             "smpl": "{L}_Wrist", "smplx": "{left}_wrist", "xsens": "{Left}Wrist", "motive": "{L}Hand",
             "asf": "{l}wrist", "unreal": "hand_{l}"},
    "Shoulder": {"unity": "Shoulder_{L}", "poser": "{l}Collar", "blender": "shoulder.{L}",
                 "biped": "Bip01 {L} Clavicle", "vrm": "J_Bip_{L}_Shoulder",
                 "smpl": "{L}_Collar", "smplx": "{left}_collar", "xsens": "{Left}Collar", "motive": "{L}Shoulder",
                 "asf": "{l}clavicle", "unreal": "clavicle_{l}"},
    "Spine": {"unity": "Spine", "poser": "abdomen", "blender": "spine", "biped": "Bip01 Spine", "vrm": "J_Bip_C_Spine",
              "smpl": "Spine1", "smplx": "spine1", "xsens": "Chest", "motive": "Ab", "asf": "upperback",
              "unreal": "spine_01"},
    "Spine1": {"unity": "Chest", "poser": "chest", "blender": "chest", "biped": "Bip01 Spine1",
               "vrm": "J_Bip_C_Chest",
               "smpl": "Spine2", "smplx": "spine2", "xsens": "Chest2", "motive": "Chest", "asf": "thorax",
               "unreal": "spine_02"},
    "Neck": {"unity": "Neck", "poser": "neck", "blender": "neck", "biped": "Bip01 Neck", "vrm": "J_Bip_C_Neck",
             "smpl": "Neck", "smplx": "neck", "xsens": "Neck", "motive": "Neck", "asf": "lowerneck",
             "unreal": "neck_01"},
    "Head": {"unity": "Head", "poser": "head", "blender": "head", "biped": "Bip01 Head", "vrm": "J_Bip_C_Head",
             "smpl": "Head", "smplx": "head", "xsens": "Head", "motive": "Head", "asf": "head", "unreal": "head"},
}


def _renamed(text: str, convention: str) -> str:
    def one(m: re.Match) -> str:
        kind, name = m.group(1), m.group(2)
        side = next((s for s in ("Left", "Right") if name.startswith(s)), None)
        base = name[len(side):] if side and name[len(side):] in _SEGMENTS else name
        if base not in _SEGMENTS or (side is None and base != name):
            return f"{kind} x_{name}"  # a joint the convention does not name (finger, hip joint, neck1)
        pattern = _SEGMENTS[base][convention]
        s = side or "Left"
        return f"{kind} " + pattern.format(L=s[0], l=s[0].lower(), Left=s, left=s.lower())
    return re.sub(r"\b(ROOT|JOINT) (\S+)", one, text)


@needs_cmu
@pytest.mark.parametrize("convention", ["unity", "poser", "blender", "biped", "vrm", "smpl", "smplx", "xsens",
                                        "motive", "asf", "unreal"])
def test_renamed_cmu_clip_gives_the_same_operator(tmp_path, convention):
    original = (MOCAP / "cmu" / "02_01.bvh").read_text()
    path = tmp_path / f"02_01_{convention}.bvh"
    path.write_text(_renamed(original, convention))
    ref, rec = BvhRecording(MOCAP / "cmu" / "02_01.bvh"), BvhRecording(path)
    assert np.abs(rec.performer.pos_world - ref.performer.pos_world).max() < 1e-3  # [m], whole clip
    assert np.abs(rec.performer.quat_wxyz - ref.performer.quat_wxyz).max() < 1e-6


def _anonymous(text: str) -> str:
    count = iter(range(10_000))
    return re.sub(r"\b(ROOT|JOINT) (\S+)", lambda m: f"{m.group(1)} j{next(count)}", text)


@needs_cmu
def test_anonymous_joint_names_are_matched_by_structure(tmp_path):
    original = (MOCAP / "cmu" / "02_01.bvh").read_text()
    path = tmp_path / "02_01_anonymous.bvh"
    path.write_text(_anonymous(original))
    ref, rec = BvhRecording(MOCAP / "cmu" / "02_01.bvh"), BvhRecording(path)
    assert all(how.startswith(("structure", "parent of")) for _, how in rec.matches.values())
    assert np.abs(rec.performer.pos_world - ref.performer.pos_world).max() < 1e-3  # [m], whole clip
    assert np.abs(rec.performer.quat_wxyz - ref.performer.quat_wxyz).max() < 1e-6


@needs_cmu_dev
def test_structure_finds_the_named_joints_of_every_shared_skeleton(tmp_path):
    """Anonymised, every shared BVH gives the joints its names give. Exception, stated: the CMU 131 and
    jumping_jacks skeleton names its upper neck ``Neck`` above a ``lowerneck`` on the chest; structure takes the
    first neck joint above the chest, the lower one."""
    for f in sorted(MOCAP.glob("*/*.bvh")):
        text = f.read_text()
        names = re.findall(r"\b(?:ROOT|JOINT) (\S+)", text)
        path = tmp_path / f.name
        path.write_text(_anonymous(text))
        by_name = BvhRecording(f).matches
        by_structure = BvhRecording(path).matches
        for canon, (name, _) in by_name.items():
            got = by_structure[canon][0]
            got = names[int(got[1:].removesuffix("End"))] + ("End" if got.endswith("End") else "")
            if "lowerneck" in names and canon in ("NECK", "SPINE_CHEST"):
                continue
            assert got == name, (f.name, canon)


# A rig as Blender's BVH export writes a simple metarig without hands (our own numbers, metres, y up): each arm ends
# at its forearm's end site, the clavicles (shoulder.L/R) start on the spine where the neck does, and the head is
# ``face``; numbered spine bones (spine.001).
_NO_HANDS_RIG = (
    ("pelvis", None, (0, 0.9, 0), ()), ("spine", "pelvis", (0, 0, 0), ()),
    ("spine.001", "spine", (0, 0.23, 0.01), ()), ("neck", "spine.001", (0, 0.23, -0.03), ()),
    ("face", "neck", (0, 0.18, 0), (0, -0.01, 0.03)),
    ("shoulder.L", "spine.001", (0, 0.23, -0.03), ()), ("upper_arm.L", "shoulder.L", (0.16, 0, 0), ()),
    ("forearm.L", "upper_arm.L", (0.255, 0, 0), (0.222, 0, 0)),
    ("shoulder.R", "spine.001", (0, 0.23, -0.03), ()), ("upper_arm.R", "shoulder.R", (-0.16, 0, 0), ()),
    ("forearm.R", "upper_arm.R", (-0.255, 0, 0), (-0.222, 0, 0)),
    ("thigh.L", "pelvis", (0.095, 0, 0), ()), ("shin.L", "thigh.L", (0.017, -0.33, 0), ()),
    ("foot.L", "shin.L", (0.017, -0.32, 0), (0.014, -0.062, 0.147)),
    ("thigh.R", "pelvis", (-0.095, 0, 0), ()), ("shin.R", "thigh.R", (-0.017, -0.33, 0), ()),
    ("foot.R", "shin.R", (-0.017, -0.32, 0), (-0.014, -0.062, 0.147)),
)


def _no_hands_rig_bvh(names: dict[str, str] | None = None, n_frames: int = 20) -> str:
    """A figure on :data:`_NO_HANDS_RIG` (joints renamed by ``names``) standing in its rest pose, its pelvis
    swaying sideways."""
    names = names or {}
    kids: dict[str | None, list[str]] = {}
    for name, parent, _, _ in _NO_HANDS_RIG:
        kids.setdefault(parent, []).append(name)
    rig = {name: (off, end) for name, _, off, end in _NO_HANDS_RIG}

    def block(name: str, depth: int) -> list[str]:
        pad = "  " * depth
        off, end = rig[name]
        chans = "CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation" if depth == 0 else \
            "CHANNELS 3 Xrotation Yrotation Zrotation"
        out = [pad + ("ROOT " if depth == 0 else "JOINT ") + names.get(name, name), pad + "{",
               f"{pad}  OFFSET {' '.join(str(v) for v in off)}", f"{pad}  {chans}"]
        for kid in kids.get(name, []):
            out += block(kid, depth + 1)
        if end:
            out += [f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET {' '.join(str(v) for v in end)}", pad + "  }"]
        return out + [pad + "}"]

    n_rot = len(_NO_HANDS_RIG) - 1
    rows = [" ".join(f"{v:.4f}" for v in (0.05 * np.sin(0.3 * k), 0.9, 0.0, 0, 0, 0, *[0.0] * (3 * n_rot)))
            for k in range(n_frames)]
    return "\n".join(["HIERARCHY", *block("pelvis", 0), "MOTION", f"Frames: {n_frames}", "Frame Time: 0.0416667",
                      *rows]) + "\n"


def test_an_arm_without_a_hand_ends_at_its_forearm_end_site(tmp_path):
    """By name, ``forearm.L``'s end site is the left wrist, ``spine.001`` the chest and ``face`` the head; by
    structure (the names anonymised), an arm without fingers is read as a leg is, and gives the same joints.
    Before, the names left the wrists and the head unmatched, and structure took the last joint of each arm as
    its wrist: the shoulders sat on the spine, where the clavicles start."""
    named = tmp_path / "no_hands.bvh"
    named.write_text(_no_hands_rig_bvh())
    rec = BvhRecording(named)
    assert all(how.startswith("name") for _, how in rec.matches.values())
    expected = {"SHOULDER_LEFT": "upper_arm.L", "ELBOW_LEFT": "forearm.L", "WRIST_LEFT": "forearm.LEnd",
                "WRIST_RIGHT": "forearm.REnd", "SPINE_CHEST": "spine.001", "HEAD": "face", "FOOT_LEFT": "foot.LEnd"}
    assert {k: rec.mapping[k] for k in expected} == expected
    pos = rec.performer.pos_world[0]
    shoulders = pos[JOINT_INDEX["SHOULDER_LEFT"]] - pos[JOINT_INDEX["SHOULDER_RIGHT"]]
    assert 0.25 < np.linalg.norm(shoulders) * 1.75 / rec.stature_m < 0.4  # [m], at his 1.75 m
    anonymous = tmp_path / "no_hands_anonymous.bvh"
    anonymous.write_text(_anonymous(named.read_text()))
    order = [name for name, _, _, _ in _NO_HANDS_RIG]
    by_structure = BvhRecording(anonymous).mapping
    for canon, name in rec.mapping.items():
        got = by_structure[canon]
        assert order[int(got[1:].removesuffix("End"))] + ("End" if got.endswith("End") else "") == name, canon


def test_a_tree_that_is_no_humanoid_fails_with_the_missing_segments():
    with pytest.raises(SourceError, match="KNEE_LEFT.*by structure: no joint with three chains"):
        match_joints(["a", "b", "c"], None, [-1, 0, 1], np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0.0]]))


def test_missing_segments_are_named(tmp_path):
    with pytest.raises(SourceError, match="KNEE_LEFT"):
        match_joints(["Hips", "Spine", "Neck", "Head", "LeftUpLeg"])


@needs_cmu_dev
def test_every_shared_bvh_loads():
    for path in sorted(MOCAP.glob("*/*.bvh")):
        rec = BvhRecording(path)
        assert 1.2 < rec.stature_m < 2.0, path.name
        assert rec.performer.duration_s > 1.0, path.name


@needs_cmu_dev
def test_inspect_shows_the_map_and_names_what_is_missing(tmp_path, capsys):
    assert cli_main(["inspect", str(MOCAP / "cmu-dev" / "02_02.bvh")]) == 0
    out = capsys.readouterr().out
    assert "KNEE_LEFT       <- lShin" in out and "up axis: +y" in out and "120.0 Hz" in out
    bad = tmp_path / "one_joint.bvh"
    bad.write_text("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation "
                   "Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n"
                   "0 0 0 0 0 0\n")
    assert cli_main(["inspect", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "KNEE_LEFT" in err and "HIP_RIGHT" in err


def _rewritten(text: str, factor: float = 1.0, axes: np.ndarray | None = None, order: str | None = None,
               six_channels: bool = False) -> str:
    """The same motion written otherwise: lengths times ``factor`` (units), every vector in axes ``axes`` (each
    joint's rotation R -> A R A^T), the rotation channels in Euler ``order`` (e.g. "XYZ"), position channels on
    every joint (Unity), all re-derived from the file's own channels (BVH: intrinsic rotations in channel order)."""
    from scipy.spatial.transform import Rotation

    A = np.eye(3) if axes is None else axes
    head, motion = text.split("MOTION", 1)
    joints: list[list[str]] = []  # per joint: its channel names, in file order
    out_head = []
    for line in head.splitlines():
        words = line.split()
        pad = line[: len(line) - len(line.lstrip())]
        if words and words[0] == "OFFSET":
            v = A @ (np.array([float(w) for w in words[1:4]]) * factor)
            out_head.append(f"{pad}OFFSET {v[0]:.6f} {v[1]:.6f} {v[2]:.6f}")
            if joints and joints[-1] == ["offset-pending"]:
                joints[-1] = ["offset", *map(str, v)]
        elif words and words[0] == "CHANNELS":
            chans = words[2:]
            offset = joints.pop() if joints and joints[-1][0] == "offset" else None
            rot_order = "".join(c[0] for c in chans if c.endswith("rotation"))
            new = [c for c in chans if c.endswith("position")]
            if six_channels and not new:
                new = ["Xposition", "Yposition", "Zposition"]
            new += [f"{c}rotation" for c in (order or rot_order)]
            joints.append([" ".join(chans), " ".join(new), offset[1:] if offset else []])
            out_head.append(f"{pad}CHANNELS {len(new)} {' '.join(new)}")
        else:
            if words and words[0] in ("ROOT", "JOINT"):
                joints.append(["offset-pending"])
            elif words and words[0] == "End":
                joints.append(["end"])
            elif words == ["}"] and joints and joints[-1] == ["end"]:
                joints.pop()
            out_head.append(line)
    lines = motion.strip().splitlines()
    rows = np.array([[float(w) for w in ln.split()] for ln in lines[2:]])
    cols, k = [], 0
    for old, new, offset in joints:
        old_c, new_c = old.split(), new.split()
        block = rows[:, k:k + len(old_c)]
        k += len(old_c)
        pos = np.array([block[:, old_c.index(f"{a}position")] for a in "XYZ"]).T if "Xposition" in old_c else None
        rord = "".join(c[0] for c in old_c if c.endswith("rotation"))
        ang = block[:, [old_c.index(f"{a}rotation") for a in rord]]
        R = A @ Rotation.from_euler(rord.upper(), ang, degrees=True).as_matrix() @ A.T
        nord = "".join(c[0] for c in new_c if c.endswith("rotation"))
        ang_new = Rotation.from_matrix(R).as_euler(nord.upper(), degrees=True)
        for c in new_c:
            if c.endswith("position"):
                p = (pos * factor) @ A.T if pos is not None else np.tile([float(x) for x in offset], (len(rows), 1))
                cols.append(p[:, "XYZ".index(c[0])])
            else:
                cols.append(ang_new[:, nord.index(c[0])])
    body = np.array(cols).T
    return ("\n".join(out_head) + "\nMOTION\n" + "\n".join(lines[:2]) + "\n"
            + "\n".join(" ".join(f"{v:.6f}" for v in r) for r in body) + "\n")


@needs_cmu
@pytest.mark.parametrize("variant", ["mm", "inch", "z_up", "euler_xyz", "unity_six_channels_cm"])
def test_units_axes_euler_order_and_channels_give_the_same_operator(tmp_path, variant):
    from stylesync.sources.bvh import _axes_matrix

    original = (MOCAP / "cmu" / "02_01.bvh").read_text()
    cmu_to_m = 0.056444
    kwargs = {
        "mm": {"factor": cmu_to_m * 1000}, "inch": {"factor": cmu_to_m / 0.0254},
        "z_up": {"axes": _axes_matrix(2, 1.0).T @ _axes_matrix(1, 1.0)}, "euler_xyz": {"order": "XYZ"},
        "unity_six_channels_cm": {"factor": cmu_to_m * 100, "six_channels": True},
    }[variant]
    path = tmp_path / f"02_01_{variant}.bvh"
    text = _rewritten(original, **kwargs)
    if variant == "unity_six_channels_cm":
        text = _renamed(text, "unity")
    path.write_text(text)
    ref, rec = BvhRecording(MOCAP / "cmu" / "02_01.bvh"), BvhRecording(path)
    assert np.abs(rec.performer.pos_world - ref.performer.pos_world).max() < 1e-3  # [m], whole clip
    q_err = np.abs(np.abs(np.sum(rec.performer.quat_wxyz * ref.performer.quat_wxyz, axis=-1)) - 1.0).max()
    assert q_err < 1e-6

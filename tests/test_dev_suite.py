"""``stylesync bench --suite dev``: the development suite per category, stylesync and the plain PD tracker."""

import json

import numpy as np
import pytest

from stylesync.cli import main as cli_main
from stylesync.metrics.dev_suite import CATEGORIES, clip_specs, fall_endings, table, termination_causes


def test_every_shared_clip_has_a_category(tmp_path):
    from pathlib import Path

    mocap = Path(__file__).resolve().parents[2] / "shared" / "mocap"
    specs = clip_specs(mocap if mocap.is_dir() else None)
    assert {"walk", "jump", "kick", "acrobatics"} <= {cat for _, _, cat in specs}
    assert all(cat != "other" for _, _, cat in specs), [n for _, n, c in specs if c == "other"]
    assert set(CATEGORIES.values()) <= {"walk", "styled walk", "uneven", "run", "jump", "kick", "arms", "acrobatics"}


def test_the_dev_suite_writes_one_row_per_category_and_controller(tmp_path, capsys):
    out = tmp_path / "dev"
    assert cli_main(["bench", "--suite", "dev", "--only", "kick", "--seeds", "1", "--seed", "3", "--duration", "1.5",
                     "--workers", "1", "--out", str(out)]) == 0
    rows = json.loads((out / "dev_suite.json").read_text())
    assert {r["seed"] for r in rows} == {3}  # --seed is the first sensor seed run (held-out seeds)
    clips = {r["clip"] for r in rows}
    assert {"kick", "spinkick"} <= clips
    for clip in clips:
        assert {r["version"] for r in rows if r["clip"] == clip} == {"stylesync", "plain-pd"}
    assert all(r["category"] == "kick" and "error" not in r for r in rows)
    md = (out / "dev_suite.md").read_text()
    assert "| kick | stylesync |" in md and "| kick | plain-pd |" in md
    paired = md.split("p (exact McNemar)", 1)[1]  # then each version paired with the first, run by run
    assert "| kick | plain-pd | " in paired and "| all | plain-pd | " in paired
    assert "dev_suite.md" in (out / "report.html").read_text()
    assert table(rows, ["stylesync"]).count("| kick |") == 1


def test_the_dev_suite_runs_the_mirror_images_of_its_clips_through_a_noisier_sensor(tmp_path, capsys):
    out = tmp_path / "mirrored"
    assert cli_main(["bench", "--suite", "dev", "--only", "kick", "--seeds", "1", "--duration", "1.0",
                     "--workers", "1", "--mirror", "--sensor-noise", "4", "--out", str(out)]) == 0
    rows = json.loads((out / "dev_suite.json").read_text())
    assert rows and all(r.get("mirror") is True and r.get("sensor_noise") == 4 and "error" not in r for r in rows)
    md = (out / "dev_suite.md").read_text()
    assert md.startswith("The sensor model's noise 4 times the default's") and "20 mm, 0.08 rad" in md
    assert "Every clip mirrored left-right" in md


def test_the_sensor_noise_reaches_the_frames():
    from stylesync.config import OperatorConfig
    from stylesync.metrics.dev_suite import operator_variant
    from stylesync.sources.registry import open_source

    assert operator_variant(OperatorConfig()) == {} and operator_variant(None) == {}
    spread = {}
    for factor in (1.0, 4.0):
        op = OperatorConfig(position_noise_m=0.005 * factor, orientation_noise_rad=0.02 * factor)
        frames = open_source("deepmimic:walk", operator=op, seed=0, duration_s=2.0).source.poll(2.0)
        clean = open_source("deepmimic:walk", operator=OperatorConfig(position_noise_m=0.0, orientation_noise_rad=0.0,
                                                                     timestamp_jitter_s=0.0),
                            seed=0, duration_s=2.0).source.poll(2.0)
        n = min(len(frames), len(clean))
        errors = [f.pos("HEAD") - g.pos("HEAD") for f, g in zip(frames[:n], clean[:n], strict=True)]
        spread[factor] = float(np.std(errors))
    assert spread[4.0] == pytest.approx(4 * spread[1.0], rel=0.3)


def test_an_unknown_category_is_one_line(tmp_path, capsys):
    assert cli_main(["bench", "--suite", "dev", "--only", "swimming", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("stylesync: error:") and "swimming" in err and "\n" not in err


def test_falls_are_counted_by_how_they_ended():
    """The table's fall endings come from the session's fall reasons; its rows have the header's columns."""
    base = {"category": "run", "version": "v", "clip_end_s": 5.0, "uhc_fall_time_s": None, "mpjpe_global_mm": 1.0,
            "mpjpe_root_mm": 1.0, "character_steps": 1, "operator_steps": 1, "path_progress": None,
            "state_transition_delay_s": {"count": 0}}
    reasons = ["pelvis at 0.49 m < 0.5 m", "pelvis at 0.50 m < 0.5 m", "a link other than a foot touched the ground",
               "the motion diverged (a link at 60 m/s, pelvis at 0.8 m; limits 25 m/s, 2.5 m)"]
    rows = [{**base, "fell": True, "fall_time_s": 1.0, "fall_reason": r} for r in reasons]
    rows += [{**base, "fell": False, "fall_time_s": None, "fall_reason": ""},
             {**base, "fell": True, "fall_time_s": 2.0}]  # a version that did not record the reason
    assert fall_endings(rows) == "2/1/1"
    header, rule, row = table(rows, ["v"]).splitlines()
    assert header.count("|") == rule.count("|") == row.count("|")
    assert "| 2/1/1 |" in row


def test_terminations_are_counted_by_their_cause():
    """The table's UHC terminations come from each run's cause (imitation.termination_split); a run that fell, or
    one without a termination, is not counted, nor one whose cause was not recorded."""
    base = {"category": "walk", "version": "v", "clip_end_s": 5.0, "mpjpe_global_mm": 1.0, "mpjpe_root_mm": 1.0,
            "character_steps": 1, "operator_steps": 1, "path_progress": None, "fall_time_s": None,
            "state_transition_delay_s": {"count": 0}, "fell": False}
    causes = ["behind", "behind", "aside", "height", "in place"]
    rows = [{**base, "uhc_fall_time_s": 1.0, "uhc_cause": c} for c in causes]
    rows += [{**base, "uhc_fall_time_s": None, "uhc_cause": None},
             {**base, "uhc_fall_time_s": 1.0, "uhc_cause": "behind", "fell": True, "fall_time_s": 2.0},
             {**base, "uhc_fall_time_s": 1.0}]  # a version that did not record the cause
    assert termination_causes(rows) == "2/0/1/1/0/1"
    header, rule, row = table(rows, ["v"]).splitlines()
    assert header.count("|") == rule.count("|") == row.count("|")
    assert "| 2/0/1/1/0/1 |" in row and "behind / ahead / aside / height / pose / in place" in header


def test_the_dev_suite_runs_the_follow_path_and_in_place_settings_beside_the_default(tmp_path, capsys):
    from stylesync.metrics.dev_suite import FOLLOW_PATH_VERSION, IN_PLACE_VERSION, run_clip

    out = tmp_path / "fp"
    assert cli_main(["bench", "--suite", "dev", "--only", "kick", "--seeds", "1", "--duration", "1.0",
                     "--workers", "1", "--follow-path", "--in-place", "--out", str(out)]) == 0
    rows = json.loads((out / "dev_suite.json").read_text())
    assert {r["version"] for r in rows} == {"stylesync", FOLLOW_PATH_VERSION, IN_PLACE_VERSION, "plain-pd"}
    assert "| kick | follow-path |" in (out / "dev_suite.md").read_text()
    assert "| kick | in-place |" in (out / "dev_suite.md").read_text()
    # The settings reach the run: 3 s of the built-in walk (his first steps from 1.3 s) go further along his path by
    # default than in place, and further still with the pull at every speed of his (by default it fades out as his
    # way goes from 0.5 to 0.7 m/s; measured: 0.196, 0.596, 0.690)
    in_place, default, follow = (run_clip("builtin:walk", 0, 3.0, v)
                                 for v in (IN_PLACE_VERSION, "stylesync", FOLLOW_PATH_VERSION))
    assert default["path_progress"] > in_place["path_progress"] + 0.25, (in_place, default)
    assert follow["path_progress"] > default["path_progress"] + 0.05, (default, follow)
    # bench options only with the dev suite
    assert cli_main(["bench", "--follow-path", "--out", str(tmp_path / "b")]) == 2
    assert cli_main(["bench", "--in-place", "--out", str(tmp_path / "b")]) == 2
    assert cli_main(["bench", "--pelvis-joint", "--out", str(tmp_path / "b")]) == 2


def test_the_dev_suite_runs_the_pelvis_joint_settings_beside_the_default(tmp_path):
    from stylesync.metrics.dev_suite import PELVIS_JOINT_VERSION, run_clip

    out = tmp_path / "pj"
    assert cli_main(["bench", "--suite", "dev", "--only", "kick", "--seeds", "1", "--duration", "1.0",
                     "--workers", "1", "--pelvis-joint", "--out", str(out)]) == 0
    rows = json.loads((out / "dev_suite.json").read_text())
    assert {r["version"] for r in rows} == {"stylesync", PELVIS_JOINT_VERSION, "plain-pd"}
    assert "| kick | pelvis-joint |" in (out / "dev_suite.md").read_text()
    # The settings reach the run: the built-in walk's 3 s differ from the default's (the pelvis not lowered as he
    # starts)
    default, joint = (run_clip("builtin:walk", 0, 3.0, v) for v in ("stylesync", PELVIS_JOINT_VERSION))
    assert default["mpjpe_root_mm"] != joint["mpjpe_root_mm"]


# A standing figure in a small BVH (centimetres, Y up, MotionBuilder names; T-pose rest, every rotation zero):
# (name, parent, offset)
_FIGURE = [("Hips", None, (0, 95, 0)), ("LeftUpLeg", "Hips", (10, 0, 0)), ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
           ("LeftFoot", "LeftLeg", (0, -42, 0)), ("LeftToeBase", "LeftFoot", (0, -5, 14)),
           ("RightUpLeg", "Hips", (-10, 0, 0)), ("RightLeg", "RightUpLeg", (0, -42, 0)),
           ("RightFoot", "RightLeg", (0, -42, 0)), ("RightToeBase", "RightFoot", (0, -5, 14)),
           ("Spine", "Hips", (0, 25, 0)), ("Neck", "Spine", (0, 25, 0)), ("Head", "Neck", (0, 15, 0)),
           ("LeftArm", "Spine", (18, 22, 0)), ("LeftForeArm", "LeftArm", (28, 0, 0)),
           ("LeftHand", "LeftForeArm", (25, 0, 0)), ("RightArm", "Spine", (-18, 22, 0)),
           ("RightForeArm", "RightArm", (-28, 0, 0)), ("RightHand", "RightForeArm", (-25, 0, 0))]


def _standing_bvh(path, frames: int = 30):
    def block(name: str, depth: int) -> list[str]:
        _, parent, (x, y, z) = next(j for j in _FIGURE if j[0] == name)
        pad, children = "  " * depth, [j[0] for j in _FIGURE if j[1] == name]
        chans = "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" if parent is None else \
            "3 Zrotation Xrotation Yrotation"
        lines = [f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}", f"{pad}{{", f"{pad}  OFFSET {x} {y} {z}",
                 f"{pad}  CHANNELS {chans}"]
        for child in children:
            lines += block(child, depth + 1)
        if not children:
            lines += [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET 0 5 0", f"{pad}  }}"]
        return lines + [f"{pad}}}"]

    row = " ".join(["0", "95", "0"] + ["0"] * (3 + 3 * (len(_FIGURE) - 1)))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("HIERARCHY\n" + "\n".join(block("Hips", 0)) + f"\nMOTION\nFrames: {frames}\n"
                    "Frame Time: 0.0333333\n" + "\n".join([row] * frames) + "\n")
    return path


def test_your_own_clips_take_their_category_from_their_folders(tmp_path):
    from stylesync.metrics.dev_suite import category_of_folder, user_clip_specs

    mine = tmp_path / "mine"
    for rel in ("walk/a.bvh", "Styled-Walk/slow/b.bvh", "misc/c.bvh"):
        _standing_bvh(mine / rel)
    (mine / "notes.md").write_text("not a clip")
    specs = user_clip_specs(str(mine))
    assert [(name, cat) for _, name, cat in specs] == [("Styled-Walk/slow/b", "styled walk"), ("misc/c", "other"),
                                                       ("walk/a", "walk")]
    assert all(spec.startswith("bvh:") and spec.endswith(".bvh") for spec, _, _ in specs)
    assert [(n, c) for _, n, c in user_clip_specs(str(mine / "walk"))] == [("a", "walk")]  # the folder given is one
    assert category_of_folder("styled_walk") == "styled walk" and category_of_folder("walks") is None


def test_the_dev_suite_runs_your_own_clips(tmp_path, capsys):
    mine = tmp_path / "mine"
    _standing_bvh(mine / "jump" / "stand.bvh")
    (mine / "jump" / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    out = tmp_path / "dev"
    assert cli_main(["bench", "--suite", "dev", "--clips", str(mine), "--clips-only", "--seeds", "1",
                     "--duration", "1.5", "--workers", "1", "--out", str(out)]) == 0
    rows = json.loads((out / "dev_suite.json").read_text())
    # named within the folder they share (mine/jump), whose name gives their category
    assert {(r["clip"], r["version"]) for r in rows} == {(c, v) for c in ("stand", "broken")
                                                        for v in ("stylesync", "plain-pd")}
    assert all(r["category"] == "jump" for r in rows)
    assert all(("error" in r) == (r["clip"] == "broken") for r in rows)
    stand = next(r for r in rows if r["clip"] == "stand" and r["version"] == "stylesync")
    assert not stand["fell"] and stand["sim_duration_s"] > 0
    md = (out / "dev_suite.md").read_text()
    assert "| jump | stylesync | 1 | 1 |" not in md and "| jump | stylesync | 2 | 1 |" in md  # 2 runs, 1 opened


def test_own_clips_options_are_checked_in_one_line(tmp_path, capsys):
    for argv, word in ((["--suite", "dev", "--clips-only"], "--clips"),
                       (["--suite", "dev", "--clips", str(tmp_path / "none")], "none"),
                       (["--clips", str(tmp_path)], "--clips")):
        assert cli_main(["bench", *argv, "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("stylesync: error:") and word in err and "\n" not in err

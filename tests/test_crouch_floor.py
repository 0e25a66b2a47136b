"""A crouch deeper than the fall height: the pelvis target of Eq. 9 no lower than MotionConfig.pelvis_min_height_m
(docs/decisions.md, "A crouch deeper than the fall height")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import suite_run

from stylesync import session as session_module
from stylesync.config import ControlConfig, MotionConfig, SessionConfig
from stylesync.errors import ConfigError
from stylesync.experiments import squat_jump
from stylesync.experiments.common import run_session
from stylesync.model.character import ANKLE_HEIGHT_M
from stylesync.model.state import CONTACT_FORCE_N
from stylesync.motion import pose_optimization
from stylesync.motion.initial_state import initial_state
from stylesync.session import FALL_ROOT_HEIGHT_M, Session
from stylesync.sources.builtin_operator import sensed
from stylesync.sources.human_model import HumanModel


def _deep_squat(monkeypatch, floor_m: float | None):
    """`experiment squat-jump`'s scripted squat (1.75 m operator, seed 0) taken down to 45 % of his hip height."""
    monkeypatch.setattr(squat_jump, "SQUAT_DEPTH", 0.55)
    op = squat_jump.operator_of(1.75, "squat")
    duration = (squat_jump.SQUAT_START_S + squat_jump.SQUAT_DOWN_S + squat_jump.SQUAT_HOLD_S + squat_jump.SQUAT_UP_S
                + squat_jump.SETTLE_S)
    cfg = SessionConfig(duration_s=duration, seed=0, operator=op)
    cfg = cfg.replace(motion=dataclasses.replace(cfg.motion, pelvis_min_height_m=floor_m))
    human = HumanModel(op.height_m, op.mass_kg)
    source = sensed(squat_jump.squat_performer(human), op, cfg.clocks, duration + 1.0, 0, "squat")
    return run_session(Session(cfg, source), stop_on_fall=False)


def test_a_crouch_deeper_than_the_fall_height_is_followed_no_deeper_than_the_floor(monkeypatch):
    """His pelvis goes down to 0.42 m (0.39 m scaled to the character). Followed as deep as he goes, the character's
    pelvis passes the fall height (0.5 m) while it stands on both feet, and the run counts a fall (measured: 2.77 s).
    With the pelvis target no lower than 0.6 m (the default), it squats to 0.6 m, both feet down, and completes."""
    deep = _deep_squat(monkeypatch, None)
    assert deep.fell and deep.fall_time_s is not None
    t = deep.log.array("t")
    at = int(np.searchsorted(t, deep.fall_time_s))
    assert deep.log.array("contact_l")[at] > CONTACT_FORCE_N and deep.log.array("contact_r")[at] > CONTACT_FORCE_N
    bounded = _deep_squat(monkeypatch, MotionConfig().pelvis_min_height_m)
    assert not bounded.fell
    pelvis_z = bounded.log.array("ch_joints")[:, 0, 2]
    assert FALL_ROOT_HEIGHT_M + 0.08 < pelvis_z.min() < 0.65  # measured: 0.603 m
    # his crouch is followed to the floor: the character went down more than a normal squat's 0.2 m
    assert pelvis_z[0] - pelvis_z.min() > 0.2


@pytest.mark.in_place
def test_an_operator_who_lies_down_is_followed_to_the_ground(monkeypatch):
    """The floor holds a crouch, his trunk upright, not a body he takes to the ground: in the humanoid3d get-up
    (face up, seed 0) he lies on his back, and the character goes down with him, a fall by the session's rule (out
    of reach, as before the floor). Held at the floor whatever his trunk does, it stays up, crouched, while he lies,
    imitating nothing of it (measured: it falls at 2.90 s, against 1.34 s)."""
    followed = suite_run("builtin:getup_faceup", 0, MotionConfig(), ControlConfig())
    assert followed.fell and followed.fall_time_s < 2.0  # measured: 1.34 s
    monkeypatch.setattr(pose_optimization, "_CROUCH_TRUNK_COS", -2.0)  # every trunk taken for upright
    held = suite_run("builtin:getup_faceup", 0, MotionConfig(), ControlConfig())
    assert not held.fell or held.fall_time_s > followed.fall_time_s + 1.0


def test_the_pelvis_floor_must_be_positive():
    with pytest.raises(ConfigError, match="pelvis_min_height_m"):
        MotionConfig(pelvis_min_height_m=0.0)


_MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
_JUMP = _MOCAP / "cmu-dev" / "13_41.bvh"


def _from_his_crouch(tmp_path: Path) -> Path:
    """CMU-dev 13_41 (a jump) from 1.1 s on: its first frame is his crouch before the take-off, his trunk upright."""
    head, motion = _JUMP.read_text().split("MOTION", 1)
    lines = [ln for ln in motion.splitlines() if ln.strip()]
    frame_time_s = float(lines[1].split(":", 1)[1])
    frames = lines[2 + round(1.1 / frame_time_s):]
    out = tmp_path / "13_41_from_crouch.bvh"
    out.write_text(f"{head}MOTION\nFrames: {len(frames)}\nFrame Time: {frame_time_s}\n" + "\n".join(frames) + "\n")
    return out


@pytest.mark.skipif(not _JUMP.is_file(), reason="../shared/mocap/cmu-dev (CMU 13_41) is not present")
def test_a_clip_that_starts_in_a_crouch_starts_above_the_fall_height(tmp_path, monkeypatch):
    """A recording started in his first pose (motion/initial_state.py) puts the pelvis where his is, scaled: in this
    crouch 0.48 m up, below the session's fall height, and the run counted a fall at 0.00 s. The start takes the
    motion stage's floor too: the pelvis at 0.6 m, the legs stretched and both feet on the ground where his are, and
    the run goes on (measured: it completes the clip and the rest on seeds 0 and 1)."""
    clip = _from_his_crouch(tmp_path)
    short = {"configure": lambda cfg: cfg.replace(duration_s=1.0)}
    started = suite_run(f"bvh:{clip}", 0, MotionConfig(), ControlConfig(), **short)
    assert not started.fell
    pelvis_z = started.log.array("ch_joints")[:, 0, 2]
    assert pelvis_z[0] == pytest.approx(MotionConfig().pelvis_min_height_m, abs=0.03)
    ankles_z = [started.log.array(side)[0] for side in ("al_z", "ar_z")]
    assert min(ankles_z) == pytest.approx(ANKLE_HEIGHT_M, abs=0.005)  # the lower foot on the ground
    assert max(ankles_z) < ANKLE_HEIGHT_M + 0.03  # the other as far above it as his (measured: 0.023 m, as without)

    def unfloored(*args):  # the start in his pose as it is, the floor left to the motion stage alone
        return initial_state(*args[:5])

    monkeypatch.setattr(session_module, "initial_state", unfloored)
    as_his = suite_run(f"bvh:{clip}", 0, MotionConfig(), ControlConfig(), **short)
    assert as_his.fell and as_his.fall_time_s < 0.05

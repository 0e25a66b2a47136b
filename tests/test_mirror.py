"""The operator's mirror image (sources/mirror.py, OperatorConfig.mirror, --mirror)."""

from __future__ import annotations

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.config import OperatorConfig, SessionConfig
from stylesync.sources.base import RecordedSource
from stylesync.sources.builtin_operator import ClipPerformer, builtin_operator
from stylesync.sources.deepmimic_clip import DeepMimicClip
from stylesync.sources.frame import JOINT_INDEX, K4ABT_JOINTS, N_JOINTS, OperatorFrame
from stylesync.sources.human_model import HumanModel
from stylesync.sources.mirror import MirroredSource, mirror_frame

REFLECT = np.diag([1.0, -1.0, 1.0])  # the x-z plane's reflection


def _walker_frame(t_s: float) -> OperatorFrame:
    """A frame of the built-in walk mid-stride (every joint tracked, segments turned every way)."""
    return ClipPerformer(DeepMimicClip.builtin("walk"), HumanModel(1.75, 75.8), 1.0).frame_at(t_s)


def _other_side(name: str) -> str:
    if name.endswith("_LEFT"):
        return name[:-5] + "_RIGHT"
    return name[:-6] + "_LEFT" if name.endswith("_RIGHT") else name


def test_a_mirror_image_swaps_the_sides_and_reflects_positions_and_orientations():
    f = _walker_frame(2.3)
    f.confidence = np.linspace(0.1, 1.0, N_JOINTS)
    before = f.joint_pos_world.copy()
    m = mirror_frame(f)
    assert np.array_equal(f.joint_pos_world, before)  # the frame given is not changed
    for name in K4ABT_JOINTS:
        j, k = JOINT_INDEX[name], JOINT_INDEX[_other_side(name)]
        assert m.joint_pos_world[j] == pytest.approx(REFLECT @ f.joint_pos_world[k], abs=1e-12)
        r_image = rot.matrix_from_quat(m.joint_quat_wxyz[j])
        assert r_image == pytest.approx(REFLECT @ rot.matrix_from_quat(f.joint_quat_wxyz[k]) @ REFLECT, abs=1e-12)
        assert np.linalg.det(r_image) == pytest.approx(1.0)  # still a rotation
        assert m.confidence[j] == f.confidence[k]
    assert m.com_world == pytest.approx(REFLECT @ f.com_world)
    # his left foot ahead becomes the right foot ahead; a turn to his left, one to the right
    assert m.pos("ANKLE_RIGHT")[1] == pytest.approx(-f.pos("ANKLE_LEFT")[1])
    turned = OperatorFrame(0.0, np.zeros((N_JOINTS, 3)), np.tile(rot.quat_from_yaw(0.4), (N_JOINTS, 1)),
                           np.ones(N_JOINTS))
    assert rot.yaw_from_quat(mirror_frame(turned).quat("PELVIS")) == pytest.approx(-0.4)
    # twice: the frame itself
    back = mirror_frame(m)
    assert back.joint_pos_world == pytest.approx(f.joint_pos_world, abs=1e-12)
    assert back.joint_quat_wxyz == pytest.approx(f.joint_quat_wxyz, abs=1e-12)
    assert np.array_equal(back.confidence, f.confidence)


def test_a_mirrored_source_passes_on_what_the_wrapped_source_knows():
    frames = [_walker_frame(1.0 + 0.1 * k) for k in range(4)]
    for k, f in enumerate(frames):
        f.timestamp_s = 0.1 * k
    frames[2].joint_pos_world = frames[2].joint_pos_world.copy()
    frames[2].joint_pos_world[3, 0] = np.nan  # rejected by the recording, counted
    inner = RecordedSource(frames, name="clip", starts_in_motion=True)
    closed = []
    inner.close = lambda: closed.append(True)  # type: ignore[method-assign]
    source = MirroredSource(inner)
    assert source.starts_in_motion and source.name == "clip"
    assert source.rejected_frames == 1
    assert not hasattr(source, "wait_first_frame")  # a recording: no live stream's wait
    got = source.poll(1.0)
    assert len(got) == 3
    assert got[0].pos("HAND_LEFT") == pytest.approx(REFLECT @ frames[0].pos("HAND_RIGHT"))
    source.close()
    assert closed == [True]


@pytest.mark.in_place
def test_the_character_follows_the_mirror_image_of_the_operator():
    # The built-in walk and its mirror image, seed 0, 4 s: the operator side (sensor noise, interpolation, 1€
    # filter, floor filter) gives exactly the reflected ankles, and the character lifts the other foot first, on
    # the same control tick. Measured: over the first 2 s the character's ankles are within 9.5 mm of the
    # reflected ones (its feet settle 4 mm towards +y in both runs alike: not the pipeline's doing, and the model's
    # left and right links are mirror images, so the engine's contact solving).
    logs = {}
    for mirror in (False, True):
        cfg = SessionConfig(duration_s=4.0, seed=0, operator=OperatorConfig(mirror=mirror))
        source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
        from stylesync.session import Session

        result = Session(cfg, source).run()
        assert not result.fell
        logs[mirror] = result.log
    plain, image = logs[False], logs[True]
    t = plain.array("t")
    assert np.array_equal(t, image.array("t"))

    def ankle(log, side: str) -> np.ndarray:
        return np.stack([log.array(f"{side}_{axis}") for axis in "xyz"], axis=1)

    assert ankle(image, "op_ar") == pytest.approx(ankle(plain, "op_al") @ REFLECT, abs=1e-12)
    assert ankle(image, "op_al") == pytest.approx(ankle(plain, "op_ar") @ REFLECT, abs=1e-12)
    early = t <= 2.0
    assert ankle(image, "ar")[early] == pytest.approx(ankle(plain, "al")[early] @ REFLECT, abs=0.02)  # 0.0095

    def first_lift_s(log, side: str) -> float:
        off = (t > 1.0) & (log.array(f"contact_{side}") < 1.0)
        return float(t[np.argmax(off)])

    assert first_lift_s(plain, "r") < first_lift_s(plain, "l")  # the walk starts on his right foot
    assert first_lift_s(image, "l") == first_lift_s(plain, "r")
    assert first_lift_s(image, "r") == first_lift_s(plain, "l")

"""The video source: MediaPipe Pose run on real frames of a file (no mock), frames timed at the file's rate, the
camera's tilt estimated and removed, and one clear line for files it cannot use."""

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS
from stylesync.sources.webcam import camera_tilt

cv2 = pytest.importorskip("cv2", reason="the webcam extra is not installed (pip install -e '.[webcam]')")
pytest.importorskip("mediapipe", reason="the webcam extra is not installed (pip install -e '.[webcam]')")


def _video(path, frames: int, fps: float = 25.0) -> None:
    out = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), fps, (320, 240))
    rng = np.random.default_rng(0)
    for k in range(frames):  # a street-grey picture with moving stripes and noise: no person in it
        img = np.full((240, 320, 3), 120, np.uint8)
        img[:, (k * 7) % 320:(k * 7) % 320 + 20] = 200
        img = np.clip(img + rng.integers(-20, 20, img.shape), 0, 255).astype(np.uint8)
        out.write(img)
    out.release()


def test_a_video_without_a_person_ends_with_one_line(tmp_path):
    from stylesync.sources.webcam import VideoRecording

    path = tmp_path / "street.avi"
    _video(path, 30)
    with pytest.raises(SourceError, match=r"no person found in 30 frames"):
        VideoRecording(path)


@pytest.mark.parametrize("content, says", [(b"", "cannot be read|no frames"),
                                           (b"RIFF\x00\x00garbage" * 50, "cannot be read|no frames")])
def test_corrupt_and_empty_video_files_end_with_one_line(tmp_path, content, says):
    from stylesync.sources.webcam import VideoRecording

    path = tmp_path / "bad.avi"
    path.write_bytes(content)
    with pytest.raises(SourceError, match=says):
        VideoRecording(path)


def test_the_cli_names_the_video_problem_in_one_line(tmp_path, capsys):
    from stylesync.cli import main as cli_main

    path = tmp_path / "street.avi"
    _video(path, 10)
    assert cli_main(["run", "--source", f"video:{path}", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no person found" in err


def test_camera_tilt_is_found_from_the_standing_legs_and_removed():
    pos = np.zeros((20, N_JOINTS, 3))
    for side, y in (("LEFT", 0.1), ("RIGHT", -0.1)):
        pos[:, JOINT_INDEX[f"HIP_{side}"]] = [0.0, y, 0.9]
        pos[:, JOINT_INDEX[f"ANKLE_{side}"]] = [0.0, y, 0.08]
    tilt = rot.matrix_from_quat(rot.quat_from_rotvec(np.array([0.0, np.radians(12.0), 0.0])))
    R, deg = camera_tilt(pos @ tilt.T)
    assert deg == pytest.approx(12.0, abs=1e-6)
    leg = (pos @ tilt.T @ R.T)[0, JOINT_INDEX["HIP_LEFT"]] - (pos @ tilt.T @ R.T)[0, JOINT_INDEX["ANKLE_LEFT"]]
    assert leg[:2] == pytest.approx([0.0, 0.0], abs=1e-9)

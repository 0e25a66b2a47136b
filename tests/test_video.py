"""The video source: MediaPipe Pose run on real frames of a file (no mock), frames timed at the file's rate, the
camera's tilt estimated and removed, and one clear line for files it cannot use."""

from pathlib import Path

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


# People walking in front of a building, filmed from a first floor: OpenCV's sample video (Debian's opencv-doc,
# installed by .ci/run; 795 frames at 10 fps, 768 x 576). Never copied into the repository.
PEOPLE_VIDEO = Path("/usr/share/doc/opencv-doc/examples/data/vtest.avi")


@pytest.mark.skipif(not PEOPLE_VIDEO.is_file(),
                    reason=f"needs the sample video of people walking {PEOPLE_VIDEO} (apt-get install opencv-doc)")
def test_a_video_of_people_walking_runs_through_mediapipe_at_the_files_rate(tmp_path):
    """MediaPipe Pose on the real frames of a recorded video of people (no mock): a person is found, his frames are
    timed at the file's rate, the camera's tilt is estimated, and a run on it exits 0 with both in its metrics."""
    import json

    from stylesync.cli import main as cli_main
    from stylesync.sources.webcam import VideoRecording

    cap = cv2.VideoCapture(str(PEOPLE_VIDEO))
    n_file, fps_file = int(cap.get(cv2.CAP_PROP_FRAME_COUNT)), float(cap.get(cv2.CAP_PROP_FPS))
    cap.release()
    rec = VideoRecording(PEOPLE_VIDEO)
    assert rec.frames == n_file == 795 and rec.frame_rate_hz == fps_file == 10.0
    times = rec.performer.times_s
    # the frames with a person, at the file's frame times (whole tenths of a second), within the file's duration
    assert np.allclose(times * fps_file, np.round(times * fps_file), atol=1e-6)
    assert times[-1] <= (n_file - 1) / fps_file + 1e-9
    assert rec.frames_without_person < 0.6 * n_file and times[-1] > 30.0
    assert np.isfinite(rec.camera_tilt_deg)
    # one person followed: from one frame with him to the next, his hips stay within the window he was searched in
    # (three people walk in this video; the pose model alone switches between them)
    from stylesync.sources.person_follower import TRAVEL_TORSOS_PER_S, WINDOW_TORSOS

    track = rec.hip_track_px
    step_px = np.linalg.norm(np.diff(track[:, 1:3], axis=0), axis=1)
    window_px = np.maximum(track[:-1, 3] * (WINDOW_TORSOS + TRAVEL_TORSOS_PER_S * np.diff(track[:, 0])), 48.0)
    assert len(track) == len(times) and np.all(step_px <= np.sqrt(2) * window_px + 1.0)
    # the run goes through the whole track (from the first frame with a person to the last) and the rest after it,
    # past a fall
    out = tmp_path / "run"
    assert cli_main(["run", "--source", f"video:{PEOPLE_VIDEO}", "--continue-after-fall", "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["video_frame_rate_hz"] == 10.0 and metrics["video_frames"] == 795
    assert metrics["camera_tilt_deg"] == pytest.approx(rec.camera_tilt_deg, abs=0.01)
    from stylesync.config import OperatorConfig

    rest_s = OperatorConfig().rest_after_clip_s
    assert metrics["sim_duration_s"] == pytest.approx(times[-1] + rest_s, abs=0.02)
    assert metrics["ended_by"] == "duration"


class _BoxPose:
    """A stand-in for MediaPipe Pose on images of boxes: each person is a box of his own value in channel 0, and the
    pose found is that of the biggest box in the image (MediaPipe's "most prominent person"), its hips at the box's
    centre and its shoulders a third of the box's height above."""

    def process(self, rgb):
        from types import SimpleNamespace

        ids = [v for v in np.unique(rgb[..., 0]) if v]
        if not ids:
            return SimpleNamespace(pose_landmarks=None, pose_world_landmarks=None)
        boxes = {}
        for v in ids:
            ys, xs = np.nonzero(rgb[..., 0] == v)
            boxes[v] = (xs.min(), ys.min(), xs.max() + 1, ys.max() + 1)
        x0, y0, x1, y1 = max(boxes.values(), key=lambda b: (b[2] - b[0]) * (b[3] - b[1]))
        h, w = rgb.shape[:2]
        hip, shoulder = ((x0 + x1) / 2 / w, (y0 + y1) / 2 / h), ((x0 + x1) / 2 / w, ((y0 + y1) / 2 - (y1 - y0) / 3) / h)
        image = [SimpleNamespace(x=0.0, y=0.0) for _ in range(33)]
        for k in (23, 24):
            image[k] = SimpleNamespace(x=hip[0], y=hip[1])
        for k in (11, 12):
            image[k] = SimpleNamespace(x=shoulder[0], y=shoulder[1])
        world = [SimpleNamespace(x=0.0, y=0.0, z=0.0, visibility=1.0) for _ in range(33)]
        return SimpleNamespace(pose_landmarks=SimpleNamespace(landmark=image),
                               pose_world_landmarks=SimpleNamespace(landmark=world))


def test_one_person_is_followed_when_a_more_prominent_one_comes_into_view():
    """Person 1 walks left to right; person 2, bigger (nearer the camera), walks in at the far side from t = 1 s.
    The pose model alone would switch to person 2; the follower stays with person 1 (person_follower.py)."""
    from stylesync.sources.person_follower import PersonFollower

    def image(t: float) -> np.ndarray:
        img = np.zeros((480, 640, 3), np.uint8)
        x1 = int(100 + 60 * t)  # person 1: 30 x 90 px, 60 px/s
        img[200:290, x1:x1 + 30, 0] = 1
        if t >= 1.0:
            x2 = int(560 - 40 * (t - 1.0))  # person 2: 50 x 150 px
            img[150:300, x2:x2 + 50, 0] = 2
        return img

    follower, alone = PersonFollower(_BoxPose()), _BoxPose()
    for k in range(40):  # 4 s at 10 fps
        t = 0.1 * k
        found = follower.find(image(t), t)
        assert found is not None
        assert abs(found.hip_px[0] - (int(100 + 60 * t) + 15)) <= 1, f"t = {t:.1f} s: followed {found.hip_px}"
    hip_alone = alone.process(image(2.0)).pose_landmarks.landmark[23].x * 640
    assert hip_alone > 400  # on its own, the pose model takes person 2

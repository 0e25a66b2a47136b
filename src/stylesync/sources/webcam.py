"""MediaPipe Pose as an operator source (``webcam:INDEX``, ``video:PATH``), an optional extra.

Needs ``pip install 'stylesync[webcam]'`` (mediapipe 0.10.21, the last release that ships its pose model inside
the wheel, and opencv). Uses ``mp.solutions.pose`` (model_complexity=1) world landmarks: metres, origin between
the hips, axes of the image (x right, y down, z away from the camera), mapped to our world as for a level depth
camera. Limits: one monocular camera, so depth is inferred and noisy, the body's position in the room is not
measured (the pelvis stays at the origin: the operator's steps show in the legs, not as travel), there is no
point cloud, and the hands and feet are coarse. Landmarks with visibility below 0.5 are marked as lost.
"""

from __future__ import annotations

import numpy as np

from stylesync.errors import SourceError
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS
from stylesync.sources.k4abt_json import R_WORLD_CAMERA
from stylesync.sources.live_positions import LivePositionSource

# canonical joint -> BlazePose landmark indices averaged
BLAZEPOSE: dict[str, tuple[int, ...]] = {
    "PELVIS": (23, 24), "NECK": (11, 12), "HEAD": (7, 8), "NOSE": (0,),
    "SHOULDER_LEFT": (11,), "ELBOW_LEFT": (13,), "WRIST_LEFT": (15,), "SHOULDER_RIGHT": (12,),
    "ELBOW_RIGHT": (14,), "WRIST_RIGHT": (16,), "HIP_LEFT": (23,), "KNEE_LEFT": (25,), "ANKLE_LEFT": (27,),
    "FOOT_LEFT": (31,), "HIP_RIGHT": (24,), "KNEE_RIGHT": (26,), "ANKLE_RIGHT": (28,), "FOOT_RIGHT": (32,),
}
MIN_VISIBILITY = 0.5


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
            raise SourceError("webcam/video sources need MediaPipe: pip install 'stylesync[webcam]' "
                              "(mediapipe==0.10.21 and opencv-python)") from None
        if is_file:
            cap = cv2.VideoCapture(device_or_path)
        else:
            try:
                cap = cv2.VideoCapture(int(device_or_path or 0))
            except ValueError:
                raise SourceError(f"webcam index must be a number, got '{device_or_path}'") from None
        if not cap.isOpened():
            raise SourceError(f"cannot open {'video' if is_file else 'webcam'} '{device_or_path}'")
        pose = mp.solutions.pose.Pose(model_complexity=1, static_image_mode=False)

        def read():
            ok, image = cap.read()
            if not ok:
                cap.release()
                return None
            res = pose.process(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))
            if res.pose_world_landmarks is None:
                return np.full((N_JOINTS, 3), np.nan), np.zeros(N_JOINTS)
            lm = res.pose_world_landmarks.landmark
            xyz = np.array([[p.x, p.y, p.z] for p in lm])
            vis = np.array([p.visibility for p in lm])
            return canonical_from_landmarks(xyz, vis)

        super().__init__(read, name=f"{'video' if is_file else 'webcam'}:{device_or_path}")

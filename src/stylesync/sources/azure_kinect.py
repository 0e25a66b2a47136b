"""Live Azure Kinect through the official Body Tracking SDK (``k4a:DEVICE``), an optional extra.

Needs the Azure Kinect Sensor SDK and Body Tracking SDK (native libraries from Microsoft) and their Python
binding ``pykinect_azure`` (``pip install 'stylesync[kinect]'``). Joint positions (mm, depth camera frame) are
read per body frame for the first body; orientations are derived from positions as for ``k4a-json`` files.
"""

from __future__ import annotations

import numpy as np

from stylesync.errors import SourceError
from stylesync.sources.frame import N_JOINTS
from stylesync.sources.k4abt_json import R_WORLD_CAMERA
from stylesync.sources.live_positions import LivePositionSource

K4ABT_CONFIDENCE_MEDIUM = 2  # k4abt_joint_confidence_level_t


class AzureKinectSource(LivePositionSource):
    def __init__(self, device_index: int = 0):
        try:
            import pykinect_azure as pykinect  # type: ignore[import-not-found]
        except ImportError:
            raise SourceError("the live Azure Kinect source needs the Azure Kinect Sensor SDK, the Body Tracking "
                              "SDK and pip install 'stylesync[kinect]' (pykinect_azure)") from None
        try:
            pykinect.initialize_libraries(track_body=True)
            config = pykinect.default_configuration
            config.depth_mode = pykinect.K4A_DEPTH_MODE_NFOV_UNBINNED
            device = pykinect.start_device(device_index=device_index, config=config)
            tracker = pykinect.start_body_tracker()
        except Exception as exc:  # noqa: BLE001 - the native SDK reports failures in many ways
            raise SourceError(f"cannot start Azure Kinect {device_index}: {exc}".splitlines()[0]) from None

        def read():
            device.update()
            frame = tracker.update()
            if frame.get_num_bodies() < 1:
                return np.full((N_JOINTS, 3), np.nan), np.zeros(N_JOINTS)
            skeleton = frame.get_body_skeleton(0)
            xyz = np.array([[j.position.x, j.position.y, j.position.z] for j in skeleton.joints]) * 1e-3
            conf = np.array([float(j.confidence_level >= K4ABT_CONFIDENCE_MEDIUM) for j in skeleton.joints])
            return xyz @ R_WORLD_CAMERA.T, conf

        super().__init__(read, name=f"k4a:{device_index}")

"""What the motion stage reads from one operator sample alone, without the character (Sec. 5.2 style features,
the level root of Sec. 5.4, the upper body's joint map, the leg length of Eq. 1): it can be computed ahead of the
control tick, on the operator's side (prefetch.py), and is the same wherever it is computed."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync.motion.balance_strategy import level_root
from stylesync.motion.style_features import StyleExtractor, StyleFeatures
from stylesync.processing.body_parameters import leg_length_m
from stylesync.processing.joint_map import local_rotations
from stylesync.processing.operator_processing import OperatorSample

_SIDE_UP = {"left": "LEFT", "right": "RIGHT"}
UPPER_JOINTS = ("chest", "neck", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow")  # joint map
_STYLE = StyleExtractor()  # stateless


@dataclass(frozen=True)
class OperatorAnalysis:
    """What the motion stage reads from one operator sample alone, without the character: it can be computed
    ahead of the control tick (prefetch.py) and is the same wherever it is computed."""

    features: StyleFeatures  # Sec. 5.2
    root_quat_wxyz: np.ndarray  # the level root with the operator's heading H (Sec. 5.4)
    upper_local_wxyz: np.ndarray  # (len(UPPER_JOINTS), 4) joint-map local rotations, chest against that root
    leg_m: float  # the operator's leg length, Eq. 1 [m]


def operator_features(s: OperatorSample) -> StyleFeatures:
    """The style features F of Sec. 5.2 of one operator sample."""
    hip = {k: s.pos[f"HIP_{v}"] for k, v in _SIDE_UP.items()}
    knee = {k: s.pos[f"KNEE_{v}"] for k, v in _SIDE_UP.items()}
    ankle = {k: s.pos[f"ANKLE_{v}"] for k, v in _SIDE_UP.items()}
    shank = {k: s.quat[f"KNEE_{v}"] for k, v in _SIDE_UP.items()}
    foot = {k: s.quat[f"ANKLE_{v}"] for k, v in _SIDE_UP.items()}
    return _STYLE(hip, knee, ankle, shank, foot, s.com_world, s.quat["PELVIS"])


def upper_local(s: OperatorSample, root_quat_wxyz: np.ndarray) -> np.ndarray:
    """The upper body's joint-map rotations; the chest keeps the operator's torso orientation in the world."""
    return local_rotations(s.quat, UPPER_JOINTS, {"chest": root_quat_wxyz})


def analyse_operator(s: OperatorSample) -> OperatorAnalysis:
    features = operator_features(s)
    q_root = level_root(features.H)
    return OperatorAnalysis(features, q_root, upper_local(s, q_root), leg_length_m(s.pos, ankle_height_m=0.0))

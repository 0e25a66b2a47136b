"""A recording's held last pose: the raised foot comes down with the leg's segments kept (sources/held_pose.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stylesync.config import OperatorConfig
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame
from stylesync.sources.held_pose import lower_foot, put_feet_down
from stylesync.sources.registry import open_source

_UNEVEN = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu-dev" / "03_01.bvh"


def _frame(left_ankle: tuple[float, float, float], left_knee: tuple[float, float, float]) -> OperatorFrame:
    """A person with his right foot on the ground under the right hip and his left leg as given [m]."""
    pos = np.zeros((N_JOINTS, 3))
    for name, p in {"PELVIS": (0.0, 0.0, 0.95), "HIP_LEFT": (0.0, 0.1, 0.9), "HIP_RIGHT": (0.0, -0.1, 0.9),
                    "KNEE_RIGHT": (0.02, -0.1, 0.5), "ANKLE_RIGHT": (0.0, -0.1, 0.08),
                    "FOOT_RIGHT": (0.15, -0.1, 0.02), "KNEE_LEFT": left_knee, "ANKLE_LEFT": left_ankle}.items():
        pos[JOINT_INDEX[name]] = p
    pos[JOINT_INDEX["FOOT_LEFT"]] = pos[JOINT_INDEX["ANKLE_LEFT"]] + (0.15, 0.0, -0.06)
    return OperatorFrame(0.0, pos, np.tile([1.0, 0.0, 0.0, 0.0], (N_JOINTS, 1)), np.ones(N_JOINTS))


def _segments(f: OperatorFrame, side: str) -> tuple[float, float, float]:
    p = {j: f.pos(f"{j}_{side}") for j in ("HIP", "KNEE", "ANKLE", "FOOT")}
    return (float(np.linalg.norm(p["KNEE"] - p["HIP"])), float(np.linalg.norm(p["ANKLE"] - p["KNEE"])),
            float(np.linalg.norm(p["FOOT"] - p["ANKLE"])))


def test_raised_bent_leg_comes_down_with_its_lengths():
    # His left foot lifted behind him, the knee bent forwards: 0.3 m over the right ankle.
    f = _frame(left_ankle=(-0.15, 0.1, 0.38), left_knee=(0.2, 0.1, 0.45))
    before = _segments(f, "LEFT")
    knee_side = np.cross(f.pos("ANKLE_LEFT") - f.pos("HIP_LEFT"), f.pos("KNEE_LEFT") - f.pos("HIP_LEFT"))
    half = _frame(left_ankle=(-0.15, 0.1, 0.38), left_knee=(0.2, 0.1, 0.45))
    put_feet_down(half, 0.5)
    assert half.pos("ANKLE_LEFT")[2] == pytest.approx(0.23)  # half of the 0.3 m
    put_feet_down(f, 1.0)
    assert f.pos("ANKLE_LEFT")[2] == pytest.approx(0.08)
    assert f.pos("ANKLE_LEFT")[:2] == pytest.approx([-0.15, 0.1])  # reachable: straight down
    assert _segments(f, "LEFT") == pytest.approx(before, abs=1e-9)
    knee_side_after = np.cross(f.pos("ANKLE_LEFT") - f.pos("HIP_LEFT"), f.pos("KNEE_LEFT") - f.pos("HIP_LEFT"))
    assert float(knee_side @ knee_side_after) > 0.0  # the knee still bends the way it did
    # The standing leg and the hip are untouched.
    assert f.pos("ANKLE_RIGHT") == pytest.approx([0.0, -0.1, 0.08])
    assert f.pos("HIP_LEFT") == pytest.approx([0.0, 0.1, 0.9])


def test_trailing_foot_is_brought_in_as_it_comes_down():
    # A trailing leg almost straight, 0.5 m behind the hip, its foot 0.1 m up: straight down would need a longer
    # leg; the foot comes down nearer the hip and the leg keeps its lengths.
    hip = np.array([0.0, 0.1, 0.9])
    ankle = np.array([-0.5, 0.1, 0.18])
    knee = hip + 0.5 * (ankle - hip) + np.array([0.01, 0.0, 0.0])
    f = _frame(left_ankle=tuple(ankle), left_knee=tuple(knee))
    before = _segments(f, "LEFT")
    put_feet_down(f, 1.0)
    assert f.pos("ANKLE_LEFT")[2] == pytest.approx(0.08)
    assert -0.5 < f.pos("ANKLE_LEFT")[0] < -0.3
    assert _segments(f, "LEFT") == pytest.approx(before, abs=1e-9)
    assert np.linalg.norm(f.pos("ANKLE_LEFT") - hip) <= before[0] + before[1]


def test_a_foot_already_lowest_is_not_moved():
    f = _frame(left_ankle=(0.0, 0.1, 0.3), left_knee=(0.1, 0.1, 0.6))
    right = f.joint_pos_world.copy()
    lower_foot(f, "RIGHT", 0.0)
    put_feet_down(f, 0.0)
    assert np.array_equal(f.joint_pos_world, right)


@pytest.mark.skipif(not _UNEVEN.is_file(), reason="../shared/mocap/cmu-dev (CMU 03_01) is not present")
def test_a_clip_ending_with_a_foot_on_a_step_keeps_his_leg_length():
    # CMU 03_01 (uneven ground) ends with his left foot 0.44 m over his right: before, the foot was moved down by
    # itself and his left leg measured 1.09 m instead of 0.82 m during the rest (a 14 % smaller scale, Eq. 9).
    opened = open_source(f"bvh:{_UNEVEN}", operator=OperatorConfig(), sensor="none", seed=0)
    frames = opened.source.frames
    end_s = opened.duration_s - OperatorConfig().rest_after_clip_s

    def leg_m(f: OperatorFrame) -> float:
        return float(np.mean([_segments(f, s)[0] + _segments(f, s)[1] for s in ("LEFT", "RIGHT")]))

    during = [leg_m(f) for f in frames if end_s - 0.5 <= f.timestamp_s <= end_s]
    rest = [f for f in frames if f.timestamp_s >= end_s + 0.6]
    assert max(abs(leg_m(f) - np.mean(during)) for f in rest) < 1e-3
    last = rest[-1]
    assert last.pos("ANKLE_LEFT")[2] == pytest.approx(last.pos("ANKLE_RIGHT")[2], abs=1e-6)

"""A recording's last pose held after its end: the raised foot put down on the ground, the leg's segments kept.

A clip often ends mid-stride (or, on uneven ground, with a foot on a step). Held as it is, the character would stand
on one leg for the whole rest; so the higher foot comes down to the lower one's height. Its hip stays where it is and
the knee is placed by the two-link solution in the leg's own plane (the plane of hip, knee and ankle), so that the
thigh and the shank keep their lengths: his leg length (Eq. 1), and with it the scale of Eq. 9, stays what it was
during the clip. A trailing foot behind a leg that would have to stretch to reach the ground below it is brought in
towards the hip as it comes down. The segments' orientations are left as they were: the legs are retargeted from
the joints' positions (motion/pose_optimization.py), the feet's headings from the feet, which are moved, not turned.
"""

from __future__ import annotations

import math

import numpy as np

from stylesync.sources.frame import JOINT_INDEX, OperatorFrame

_SIDES = ("LEFT", "RIGHT")
_REACH_SHARE = 0.999  # the lowered ankle at most this share of thigh + shank from the hip: a knee still bent [-]


def _knee_in_leg_plane(hip: np.ndarray, knee: np.ndarray, ankle: np.ndarray, thigh_m: float, shank_m: float,
                       toes_dir: np.ndarray) -> np.ndarray:
    """(3,) the knee [m] that joins a thigh of ``thigh_m`` from ``hip`` to a shank of ``shank_m`` to ``ankle``, bent
    to the side the old ``knee`` is on off the hip-ankle line (law of cosines); a knee on that line (a straight
    leg) is bent towards ``toes_dir`` (ankle to toes)."""
    d = ankle - hip
    dist = float(np.linalg.norm(d))
    if dist < 1e-9:  # an ankle at the hip (a body folded up): no plane to solve in
        return knee
    axis = d / dist
    along = (thigh_m * thigh_m - shank_m * shank_m + dist * dist) / (2.0 * dist)
    off = math.sqrt(max(thigh_m * thigh_m - along * along, 0.0))
    bend = (knee - hip) - float((knee - hip) @ axis) * axis
    norm = float(np.linalg.norm(bend))
    if norm < 1e-9:  # a straight leg: bend it forwards, towards the toes
        bend = toes_dir - float(toes_dir @ axis) * axis
        norm = float(np.linalg.norm(bend))
        if norm < 1e-9:
            return hip + along * axis
    return hip + along * axis + off * bend / norm


def lower_foot(f: OperatorFrame, side: str, drop_m: float) -> None:
    """In place: lowers ``side``'s ("LEFT"/"RIGHT") ankle and toes by ``drop_m`` [m], the hip fixed, the knee
    re-placed so that thigh and shank keep their lengths. An ankle the leg would not reach so far below the hip
    (a trailing foot behind a straight leg) is brought in towards the hip's vertical as far as it needs."""
    if drop_m <= 0.0:
        return
    pos = f.joint_pos_world
    i_hip, i_knee = JOINT_INDEX[f"HIP_{side}"], JOINT_INDEX[f"KNEE_{side}"]
    i_ankle, i_foot = JOINT_INDEX[f"ANKLE_{side}"], JOINT_INDEX[f"FOOT_{side}"]
    hip, knee, ankle = pos[i_hip].copy(), pos[i_knee].copy(), pos[i_ankle].copy()
    thigh_m, shank_m = float(np.linalg.norm(knee - hip)), float(np.linalg.norm(ankle - knee))
    reach_m = _REACH_SHARE * (thigh_m + shank_m)
    target = ankle - np.array([0.0, 0.0, drop_m])
    below_m = float(hip[2] - target[2])
    if below_m >= reach_m:  # no bent leg reaches that low: the foot as low as a straight leg under the hip
        target = np.array([hip[0], hip[1], hip[2] - reach_m])
    else:
        across = target[:2] - hip[:2]
        across_m, allowed_m = float(np.linalg.norm(across)), math.sqrt(reach_m * reach_m - below_m * below_m)
        if across_m > allowed_m:
            target[:2] = hip[:2] + across * (allowed_m / across_m)
    pos[i_knee] = _knee_in_leg_plane(hip, knee, target, thigh_m, shank_m, pos[i_foot] - ankle)
    pos[i_foot] = pos[i_foot] + (target - ankle)
    pos[i_ankle] = target


def put_feet_down(f: OperatorFrame, fraction: float) -> None:
    """In place: the operator holding a pose comes to rest on both feet. The higher foot is lowered by ``fraction``
    of its ankle's height over the lower one's (:func:`lower_foot`)."""
    z = {side: float(f.pos(f"ANKLE_{side}")[2]) for side in _SIDES}
    low = min(z.values())
    for side, ankle_z in z.items():
        lower_foot(f, side, fraction * (ankle_z - low))

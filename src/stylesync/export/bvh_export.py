"""The simulated character's motion as BVH (Y up, character facing +Z, centimetres, ZXY Euler channels).

Hierarchy: the character's links (root = pelvis with 6 channels; chest, neck, hips, knees, ankles, shoulders,
elbows with 3; the fixed wrists as end sites), with offsets from the rest pose (all joints at zero, standing,
facing +x). The character's canonical link orientations are the identity in that rest pose, so a joint's BVH
rotation is its link's world orientation relative to its parent link's, ``Q_parent^-1 ⊗ Q_link``, in BVH axes.
Readable by Blender's importer and by ``bvhio``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from stylesync import rotations as rot
from stylesync.model.character import LINK_NAMES, LINK_PARENT

# ours (x forward, y left, z up) -> BVH (X left, Y up, Z forward): a cyclic permutation, a proper rotation.
R_BVH_OURS = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
Q_BVH_OURS = rot.quat_from_matrix(R_BVH_OURS)
CM_PER_M = 100.0
END_SITES = {"right_wrist", "left_wrist"}
CHANNEL_ORDER = "ZXY"  # intrinsic: Zrotation Xrotation Yrotation


def bvh_local_quats(link_quat_wxyz: np.ndarray) -> dict[str, np.ndarray]:
    """(T, n_links, 4) canonical world link orientations -> BVH local rotations (T, 4) per exported joint, BVH axes."""
    idx = {n: i for i, n in enumerate(LINK_NAMES)}
    T = len(link_quat_wxyz)
    qa = np.tile(Q_BVH_OURS, (T, 1))
    qa_inv = rot.batch_conjugate(qa)
    out = {}
    for name in LINK_NAMES:
        if name in END_SITES:
            continue
        q = link_quat_wxyz[:, idx[name]]
        par = LINK_PARENT[name]
        local = q if par is None else rot.batch_multiply(rot.batch_conjugate(link_quat_wxyz[:, idx[par]]), q)
        out[name] = rot.batch_multiply(rot.batch_multiply(qa, local), qa_inv)
    return out


def write_bvh(path: str | Path, times_s: np.ndarray, root_pos_world: np.ndarray, link_quat_wxyz: np.ndarray,
              rest_link_origin_world: np.ndarray, frame_time_s: float | None = None,
              end_sites_world: dict[str, np.ndarray] | None = None) -> None:
    """Write the motion sampled at ``times_s`` (uniform) [s]; positions [m] in our world. ``frame_time_s``: the
    file's Frame Time, the sampling clock's period (default: the median gap of ``times_s``). ``end_sites_world``:
    where the end segments end in the rest pose [m] (keys: the wrist links, the hands' tips; leaf links, e.g. the
    ankles and the neck, the toes' tips and the top of the head); without it the wrists' end sites are the wrist
    joints and the leaves' have zero length."""
    idx = {n: i for i, n in enumerate(LINK_NAMES)}
    children = {n: [c for c in LINK_NAMES if LINK_PARENT[c] == n] for n in LINK_NAMES}
    rest = rest_link_origin_world @ R_BVH_OURS.T * CM_PER_M
    ends = {k: np.asarray(v, dtype=float) @ R_BVH_OURS.T * CM_PER_M for k, v in (end_sites_world or {}).items()}
    lines = ["HIERARCHY"]
    order: list[str] = []

    def block(name: str, depth: int) -> None:
        pad = "\t" * depth
        par = LINK_PARENT[name]
        off = np.zeros(3) if par is None else rest[idx[name]] - rest[idx[par]]
        if name in END_SITES and par is not None and name in ends:
            off = ends[name] - rest[idx[par]]
        if name in END_SITES:
            lines.extend([f"{pad}End Site", f"{pad}{{", f"{pad}\tOFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}",
                          f"{pad}}}"])
            return
        order.append(name)
        lines.append(f"{pad}{'ROOT' if par is None else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}\tOFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        rot_ch = "Zrotation Xrotation Yrotation"
        lines.append(f"{pad}\tCHANNELS 6 Xposition Yposition Zposition {rot_ch}" if par is None
                     else f"{pad}\tCHANNELS 3 {rot_ch}")
        for c in children[name]:
            block(c, depth + 1)
        if not children[name]:
            tip = ends[name] - rest[idx[name]] if name in ends else np.zeros(3)
            lines.extend([f"{pad}\tEnd Site", f"{pad}\t{{",
                          f"{pad}\t\tOFFSET {tip[0]:.6f} {tip[1]:.6f} {tip[2]:.6f}", f"{pad}\t}}"])
        lines.append(f"{pad}}}")

    block("root", 0)
    local = bvh_local_quats(link_quat_wxyz)
    euler = {n: Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler(CHANNEL_ORDER, degrees=True) for n, q in local.items()}
    root_bvh = root_pos_world @ R_BVH_OURS.T * CM_PER_M
    if frame_time_s is not None:
        frame_time = float(frame_time_s)
    else:
        frame_time = float(np.median(np.diff(times_s))) if len(times_s) > 1 else 1.0 / 30.0
    lines += ["MOTION", f"Frames: {len(times_s)}", f"Frame Time: {frame_time:.8f}"]
    for k in range(len(times_s)):
        vals = list(root_bvh[k])
        for n in order:
            vals += list(euler[n][k])
        lines.append(" ".join(f"{v:.6f}" for v in vals))
    Path(path).write_text("\n".join(lines) + "\n")

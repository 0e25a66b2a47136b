"""Gravity compensation by Jacobian transpose (Sec. 6.1, Eq. 14-15).

Eq. 14-15 apply the virtual force ``f_i = -m_i g`` at each link's COM through the chain from the root to link i.
For a joint j this sums to ``τ_j = J^T (M_sub g ẑ)`` at the COM of the subtree below j. With a floating base that
alone leaves the pelvis unsupported, so, as in GENBICON [3] which the paper follows for this method, a leg whose
foot is in stance carries the links above it through the chain from its foot (the joint is then driven "in
reverse": ``τ_j = -(c_above - o_j) × (M_above g ẑ)``). A leg with stance weight w blends the two
(w = 0 swing, w = 1 full stance; the weights of the two legs sum to 1 in double stance).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.support import support_point
from stylesync.model.character import JOINTS, LINK_NAMES, subtree_links
from stylesync.model.state import CharacterState

_UP = np.array([0.0, 0.0, 1.0])

SUBTREE_MASK = np.zeros((len(JOINTS), len(LINK_NAMES)))
for _j, _spec in enumerate(JOINTS):
    SUBTREE_MASK[_j, subtree_links(_spec.name)] = 1.0
LEG_JOINTS = {side: np.array([k for k, j in enumerate(JOINTS) if j.name.startswith(side) and
                              j.name.split("_")[1] in ("hip", "knee", "ankle")]) for side in ("left", "right")}
ANKLE_JOINT = {side: next(k for k, j in enumerate(JOINTS) if j.name == f"{side}_ankle")
               for side in ("left", "right")}


def gravity_torques(
    state: CharacterState,
    frames: JointFrames,
    link_mass_kg: np.ndarray,
    gravity_mps2: float,
    stance_weight: dict[str, float],
    ankle_world: dict[str, np.ndarray],
    skip_stance_ankle: bool = False,
) -> np.ndarray:
    """Eq. 14-15 with stance-leg support. Returns the (n_joints, 3) torque layout [N·m].

    Every joint holds the weight of its subtree (Eq. 14-15). A stance leg s also receives the ground's vertical
    reaction ``F_s = w_s m g ẑ`` at its support point p_s (:func:`support_point`); the static balance of the leg
    below joint j then gives ``τ_j = (c_sub - o_j) × m_sub g ẑ - (p_s - o_j) × F_s``. In single stance this is
    the "reverse" chain of GENBICON [3] (the leg carries everything above it).
    ``skip_stance_ankle`` leaves the stance ankles' reaction part to the IPM ankle torque (Eq. 20).
    """
    m = link_mass_kg
    g_up = gravity_mps2 * _UP
    weighted = m[:, None] * state.link_com_world  # (n_links, 3)
    m_sub = SUBTREE_MASK @ m  # (n_joints,)
    c_sub = (SUBTREE_MASK @ weighted) / m_sub[:, None]
    moment = rot.cross(c_sub - frames.origin, m_sub[:, None] * g_up)  # (n_joints, 3)
    com = weighted.sum(axis=0) / m.sum()
    for side, p in support_point(com, ankle_world, stance_weight).items():
        idx = LEG_JOINTS[side]
        if skip_stance_ankle:
            idx = idx[idx != ANKLE_JOINT[side]]
        reaction = stance_weight[side] * m.sum() * g_up
        moment[idx] -= rot.cross(p[None, :] - frames.origin[idx], reaction[None, :])
    return frames.torque_from_moment(moment)

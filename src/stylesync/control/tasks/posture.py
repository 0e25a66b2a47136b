"""Joint posture: each joint DOF follows the retargeted operator pose (Eq. 13 as a desired acceleration).

``q̈*_j = ω² e_j + 2 ζ ω (q̇_ref - q̇)_j`` per DOF (gains per unit inertia, so that the light feet and hands and the
heavy trunk track alike), saturated, weighted by the DOF's own inertia ``M_jj`` (at least a floor): a tracking
error then costs about what the torque to correct it would.
"""

from __future__ import annotations

import numpy as np

from stylesync.control.tasks.base import Task, TaskRows
from stylesync.model.character import N_DOFS, ROOT_DOFS
from stylesync.model.character_model import CharacterModel


class JointPostureTask(Task):
    name = "posture"

    def __init__(self, weight: float, min_inertia_kgm2: float):
        self.weight = weight
        self.min_inertia_kgm2 = min_inertia_kgm2  # [kg·m²]
        self.desired_accel = np.zeros(N_DOFS - ROOT_DOFS)  # (n_joint_dofs,) [rad/s²], set per tick
        self._dofs = slice(ROOT_DOFS, N_DOFS)
        self.dof_scale: np.ndarray | None = None  # (n_joint_dofs,) per-DOF factor on the weight, set per tick

    def rows(self, model: CharacterModel) -> TaskRows:
        inertia = model.mass_matrix.diagonal()[ROOT_DOFS:]
        w = self.weight * np.maximum(inertia, self.min_inertia_kgm2)
        if self.dof_scale is not None:
            w = w * self.dof_scale
        return TaskRows(None, self.desired_accel, w, dofs=self._dofs)

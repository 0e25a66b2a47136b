"""Centroidal momentum: the whole body's linear and angular momentum about its COM change at a desired rate.

``ḣ = A_g q̈ + Ȧ_g q̇`` (Orin and Goswami's centroidal momentum matrix, from the model). The desired rate is the
COM virtual force and the root virtual torque of Eq. 16 (with the LIPM time-sync force of Eq. 21-23), so that with
the root's equations of motion as constraints this task asks the ground for the wrench of Eq. 16, and the contact
forces that give it are found with the accelerations (instead of Eq. 17-18's Jacobian-transpose mapping).
"""

from __future__ import annotations

import numpy as np

from stylesync.control.tasks.base import Task, TaskRows
from stylesync.model.character_model import CharacterModel


class CentroidalMomentumTask(Task):
    name = "centroidal_momentum"

    def __init__(self, force_weight: float, moment_weight: float):
        self.weight = np.array(3 * [force_weight] + 3 * [moment_weight])
        self.force_n = np.zeros(3)  # desired rate of linear momentum, m c̈* [N]
        self.moment_nm = np.zeros(3)  # desired rate of angular momentum about the COM [N·m]

    def rows(self, model: CharacterModel) -> TaskRows:
        target = np.concatenate([self.force_n, self.moment_nm]) - model.centroidal_map_dot_v
        return TaskRows(model.centroidal_map, target, self.weight)

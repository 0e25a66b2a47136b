"""A step of the character's own that does not push the body on: a bound on the ground's horizontal force.

In a step the character takes on its own (motion/recovery_step.py) the COM task asks for no horizontal force: the
body is left to its pendulum, on whose capture point the landing is planned. The swing ankle's world-space task
weighs as much as a hundred newtons of that request, and the QP met it by pushing the whole body the way the capture
point already diverges: traced on CMU-dev 08_08 (seed 11), a chain of such steps took the COM from 1.1 to 3.0 m/s
while the operator stood (docs/decisions.md, "A character's own steps that push it on").

With WholeBodyConfig.own_step_push_bound ("he_stands" by default: in the steps taken while the operator stands,
the steps that are to stop the body) the ground's horizontal force along the divergence ``u`` (the capture
point from the sole's centre) is at most the linear inverted pendulum's (the model of Eq. 21) with its centre of
pressure at the sole's rear edge along ``u``, ``m ω² (u·c - min_k u·p_k)``, and MOMENTUM_ACCEL_ALLOWANCE_MPS2 as in
contacts.feasible_horizontal_force. The linear momentum's horizontal rate is ``A_g[:2] q̈ + (Ȧ_g q̇)[:2]`` (the
centroidal map), so the bound is one inequality on q̈; braking, or a force across ``u``, is not bounded.
"""

from __future__ import annotations

import numpy as np

from stylesync.control.contacts import INFINITY, MOMENTUM_ACCEL_ALLOWANCE_MPS2
from stylesync.control.formulation import RowBound
from stylesync.model.character_model import CharacterModel


def own_step_push_bound(model: CharacterModel, corners_world: np.ndarray, mass_kg: float,
                        gravity_mps2: float) -> RowBound:
    """The horizontal force along the capture point's divergence from a sole (corners (4, 3) [m]) at most the linear
    inverted pendulum's with its centre of pressure at the sole's rear edge along that direction, and
    MOMENTUM_ACCEL_ALLOWANCE_MPS2 (WholeBodyConfig.own_step_push_bound), as a bound on q̈: the horizontal rate of the
    linear momentum is ``A_g[:2] q̈ + (Ȧ_g q̇)[:2]``."""
    com, com_vel = model.com_world, model.com_vel_world
    centre = corners_world.mean(axis=0)
    h = max(float(com[2] - centre[2]), 0.1)
    omega = (gravity_mps2 / h) ** 0.5
    d = (com + com_vel / omega - centre)[:2]
    norm = float(np.hypot(d[0], d[1]))
    u = d / norm if norm > 1e-9 else np.zeros(2)
    rear = float((corners_world[:, :2] @ u).min())
    f_max = mass_kg * (omega * omega * max(float(com[:2] @ u) - rear, 0.0) + MOMENTUM_ACCEL_ALLOWANCE_MPS2)
    row = u[0] * model.centroidal_map[0] + u[1] * model.centroidal_map[1]
    return RowBound(row, -INFINITY, f_max - float(u @ model.centroidal_map_dot_v[:2]))

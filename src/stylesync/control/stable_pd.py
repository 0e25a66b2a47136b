"""Stable (implicit) PD: Eq. 13's feedback evaluated at the next physics step (Tan, Liu & Turk 2011).

Table 3's gains on this character's light links are far past the explicit stability limit at 600 Hz (the foot's
roll inertia about the ankle is 0.0014 kg·m^2; Kd dt / I must stay below 2). Instead of lowering the gains, the
feedback is evaluated at the state the step will produce (semi-implicit Euler, as the engine integrates):

    Q = Kp (e - dt q̇) + Kd (q̇_d - q̇) - (Kd dt + Kp dt^2) q̈ ,   M q̈ = Q
    =>  Q = G r,   r = Kp (e - dt q̇) + Kd (q̇_d - q̇),   G = I - D (M + D)^-1,   D = Kd dt + Kp dt^2

with M the joint-space inertia of the floating character (root DOFs unactuated: zero gains). Contact forces,
gravity and velocity-product terms are left out of the prediction (they are not stiff), as in Tan et al.; the
gravity compensation (Eq. 14-15) and the virtual forces are added outside. D may have off-diagonal blocks: the
root virtual torque (Eq. 16, 18) is a feedback on the root's angular velocity applied through the stance hips,
and is made implicit the same way (see ``controller.py``). G is computed once per control tick (M changes slowly)
and applied at every physics step.
"""

from __future__ import annotations

import numpy as np

from stylesync.model.character import JOINT_DOF_COUNT, JOINT_DOF_START, JOINTS, N_DOFS, N_JOINT_DOFS, ROOT_DOFS

_ROWS = np.array([k for k in range(len(JOINTS)) for _ in range(JOINT_DOF_COUNT[k])])
_COLS = np.array([a for k in range(len(JOINTS)) for a in range(JOINT_DOF_COUNT[k])])
assert len(_ROWS) == N_JOINT_DOFS and all(JOINT_DOF_START[k] == int(np.argmax(_ROWS == k)) for k in range(len(JOINTS)))


def flatten_joint_values(values: np.ndarray) -> np.ndarray:
    """(n_joints, 3) per-joint values -> (N_JOINT_DOFS,) in the DOF layout (hinges keep column 0)."""
    return values[_ROWS, _COLS]


def unflatten_joint_values(flat: np.ndarray) -> np.ndarray:
    out = np.zeros((len(JOINTS), 3))
    out[_ROWS, _COLS] = flat
    return out


def joint_damping(kp: np.ndarray, kd: np.ndarray, dt_s: float) -> np.ndarray:
    """D (N_DOFS square) of the joints' PD gains (n_joints, 3): Kd dt + Kp dt^2 on the joint DOFs' diagonal, zero on
    the root's rows and columns (unactuated)."""
    d = np.zeros((N_DOFS, N_DOFS))
    j = np.arange(ROOT_DOFS, N_DOFS)
    d[j, j] = flatten_joint_values(kd * dt_s + kp * dt_s * dt_s)
    return d


def implicit_gain(mass_matrix: np.ndarray, damping_matrix: np.ndarray) -> np.ndarray:
    """G = I - D (M + D)^-1 (N_DOFS square): maps the explicit feedback r to the force it produces implicitly."""
    n = mass_matrix.shape[0]
    a = mass_matrix + damping_matrix
    # D (M + D)^-1 = ((M + D)^-T D^T)^T
    return np.eye(n) - np.linalg.solve(a.T, damping_matrix.T).T

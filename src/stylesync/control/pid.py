"""PID joint controller (Sec. 6.1, Eq. 13), run at the physics rate.

Eq. 13 is read with continuous-time gains (Table 3): τ = Kp e + Ki ∫e dt + Kd ė, e the joint error. For ball
joints e is the rotation vector of ``q_f^{-1} ⊗ q_d`` (child frame, the frame the torque acts in); for hinges the
angle difference. The derivative uses the measured joint velocity against the reference's velocity (estimated
at the control rate), which equals ė without the spikes a held 133 Hz reference would put into a finite
difference at 600 Hz. The sum is clamped (anti-windup).
"""

from __future__ import annotations

import numpy as np

from stylesync import rotations as rot
from stylesync.config import ControlConfig, pid_group
from stylesync.sim.character import JOINTS, JointKind

IS_BALL = np.array([j.kind is JointKind.BALL for j in JOINTS])


def gain_arrays(cfg: ControlConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    kp = np.array([cfg.pid[pid_group(j.name)].kp for j in JOINTS])
    ki = np.array([cfg.pid[pid_group(j.name)].ki for j in JOINTS])
    kd = np.array([cfg.pid[pid_group(j.name)].kd for j in JOINTS])
    return kp, ki, kd


def joint_error(q_current: np.ndarray, q_desired: np.ndarray) -> np.ndarray:
    """(n_joints, 3) error: child-frame rotation vector for ball joints, angle in column 0 for hinges [rad]."""
    e = np.zeros((len(q_current), 3))
    e[IS_BALL] = rot.batch_rotvec(rot.batch_multiply(rot.batch_conjugate(q_current[IS_BALL]), q_desired[IS_BALL]))
    e[~IS_BALL, 0] = q_desired[~IS_BALL, 0] - q_current[~IS_BALL, 0]
    return e


# Explicit integration of a PD on an inertia I at step dt is stable only for kd dt / I < 2 and kp dt^2 / I < ~1;
# the feet of this model (about 0.0014 kg·m^2 about the ankle's roll axis) violate it with Table 3's ankle
# Kd = 2 at 600 Hz and the joint oscillates without bound. Gains are therefore clamped to this fraction of the
# stability limit of each joint's subtree inertia (a departure from Table 3 only where it would blow up).
STABILITY_FRACTION = 0.5


def stable_gains(kp: np.ndarray, kd: np.ndarray, inertia_kgm2: np.ndarray, dt_s: float):
    """Per-axis gains (n_joints, 3) clamped to the explicit-integration limit of the axis inertia (n_joints, 3)."""
    kd_max = STABILITY_FRACTION * 2.0 * inertia_kgm2 / dt_s
    kp_max = STABILITY_FRACTION * inertia_kgm2 / dt_s**2
    return np.minimum(kp[:, None], kp_max), np.minimum(kd[:, None], kd_max)


class JointPid:
    def __init__(self, cfg: ControlConfig, dt_s: float, joint_inertia_kgm2: np.ndarray | None = None):
        kp, ki, kd = gain_arrays(cfg)
        self.kp, self.ki, self.kd = kp[:, None], ki[:, None], kd[:, None]
        if joint_inertia_kgm2 is not None:
            self.kp, self.kd = stable_gains(kp, kd, joint_inertia_kgm2, dt_s)
            # A hinge acts about its axis (model z) only.
            self.kp[~IS_BALL] = self.kp[~IS_BALL][:, 2:3]
            self.kd[~IS_BALL] = self.kd[~IS_BALL][:, 2:3]
        self.dt_s = dt_s
        self.integral_limit = cfg.integral_limit_rad_s
        self.integral = np.zeros((len(JOINTS), 3))

    def reset(self) -> None:
        self.integral[:] = 0.0

    def __call__(self, q_current: np.ndarray, qdot_current: np.ndarray, q_desired: np.ndarray,
                 qdot_desired: np.ndarray, gain_scale: np.ndarray | None = None) -> np.ndarray:
        e = joint_error(q_current, q_desired)  # Eq. 13, q_d(t+1) - q_f(t)
        self.integral = np.clip(self.integral + e * self.dt_s, -self.integral_limit, self.integral_limit)
        tau = self.kp * e + self.ki * self.integral + self.kd * (qdot_desired - qdot_current)
        if gain_scale is not None:
            tau *= gain_scale[:, None]
        return tau

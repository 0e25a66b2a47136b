"""The joints' no-load speed: a joint turning faster than it is given no torque that speeds it up further.

A muscle's force falls to zero at its maximum shortening speed (Hill's force-velocity relation); an electric
motor's torque falls to zero at its no-load speed. The character's joints, driven by the whole-body controller's
torques held over a control tick (1/133 s, 4-5 physics steps), had no such bound: a light link (a foot, a hand, a
limb turning about its own axis) given a torque the next tick did not expect (a stance foot that lifts with the
torque that was to turn it against the ground; the derivative term of a reference that jumped) spun up to the
engine's 100 rad/s within a tick, and the run ended as "the motion diverged" with the body upright
(docs/decisions.md, "The joints' no-load speed").

:func:`limit_joint_speed` removes, per joint, the part of the torque along the joint's motion once the joint turns
faster than the limit: the torque may still brake it or turn it another way. Torques and velocities are in the
joint layout of ``Torques`` and ``CharacterState.joint_vel``: ball joints' child-frame vectors, hinges in column 0
(the power τ·ω does not depend on the frame, as long as both are in the same one).
"""

from __future__ import annotations

import numpy as np


def limit_joint_speed(tau: np.ndarray, joint_vel: np.ndarray, limit_rad_s: float) -> int:
    """Remove, in place, the torque component along the motion of each joint of ``joint_vel`` (n_joints, 3)
    [rad/s] faster than ``limit_rad_s`` from ``tau`` (n_joints, 3) [N·m] where it would speed the joint up
    (τ·ω > 0). Returns the number of joints limited."""
    speed_sq = np.einsum("ij,ij->i", joint_vel, joint_vel)
    fast = speed_sq > limit_rad_s * limit_rad_s
    if not fast.any():
        return 0
    u = joint_vel[fast] / np.sqrt(speed_sq[fast])[:, None]  # the fast joints' directions of motion
    along = np.einsum("ij,ij->i", tau[fast], u)
    speeding_up = along > 0.0
    tau[fast] -= (along * speeding_up)[:, None] * u
    return int(speeding_up.sum())

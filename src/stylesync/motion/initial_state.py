"""Reference-state initialisation: the character starts a recorded clip in the clip's own first pose and velocities.

A recorded clip usually starts mid-motion (a walk mid-stride, a run at full speed). Starting the character standing
and still, the clip would start at full speed against a body that is not moving (DeepMimic's "reference state
initialisation" answers the same problem in training). Here the first operator samples are retargeted as the motion
stage does, without the character's state:

- root: level, with the operator's heading H (Sec. 5.4), at the operator's pelvis over the ground, at the height of
  Eq. 9 above the lower of his ankles, and, as the motion stage's pelvis target, no lower than
  ``MotionConfig.pelvis_min_height_m`` while his trunk is upright (a clip that starts in a deep crouch starts the
  character crouched above the session's fall height, its feet on the ground where his are);
- legs: the leg IK of Sec. 5.3 in the motion plane N of each leg, each ankle where the operator's is relative to
  his pelvis, scaled (h_C / h_H, Eq. 9), never below the ground; feet flat with the operator's foot heading;
- upper body: the joint map (as the motion stage).

Velocities are the forward differences of two such poses: the root's linear velocity is the operator's pelvis
velocity scaled by h_C / h_H (the character's strides are shorter by that ratio), angular velocities come from the
relative rotations (world frame for the root, child frame for ball joints, as ``CharacterState.joint_vel``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    HIP_HALF_WIDTH_M,
    JOINTS,
    SHANK_LENGTH_M,
    THIGH_LENGTH_M,
    JointKind,
)
from stylesync.model.sole import Point, convex_hull_points, outside_distance_points
from stylesync.motion.leg_ik import solve_leg
from stylesync.motion.operator_analysis import OperatorAnalysis
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M, below_crouch_floor, joint_targets, map_upper_body
from stylesync.motion.recovery_step import capture_point
from stylesync.processing.body_parameters import operator_pelvis_world
from stylesync.processing.operator_processing import OperatorSample

_UP = np.array([0.0, 0.0, 1.0])
_BALL = [k for k, j in enumerate(JOINTS) if j.kind is JointKind.BALL]
_HINGE = [k for k, j in enumerate(JOINTS) if j.kind is not JointKind.BALL]


@dataclass(frozen=True)
class InitialState:
    """A full character state (world frame, z up): root pose and velocities, joints in ``CharacterState`` layout."""

    root_pos_world: np.ndarray  # (3,) [m]
    root_quat_wxyz: np.ndarray  # (4,)
    joint_pos: np.ndarray  # (n_joints, 4): ball joints model-frame quaternions, hinge angle [rad] in column 0
    root_lin_vel_world: np.ndarray  # (3,) [m/s]
    root_ang_vel_world: np.ndarray  # (3,) [rad/s]
    joint_vel: np.ndarray  # (n_joints, 3): ball joints child-frame angular velocity [rad/s], hinge rate in column 0


def retargeted_pose(s: OperatorSample, analysis: OperatorAnalysis, scale: float | None = None,
                    from_hip_joints: bool = False, pelvis_min_height_m: float | None = None,
                    ankle_shift_world: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(root position [m], root quaternion, joint positions) of the character for one operator sample, the pelvis
    over the ground at the operator's, scaled by ``scale`` (default h_C / h_H of this sample, Eq. 9) from the world
    origin (differences of poses at one scale give velocities). His pelvis is the midpoint of his hip joints with
    ``from_hip_joints`` (MotionConfig.pelvis_from_hip_joints), else his skeleton's pelvis joint. While his trunk is
    upright the pelvis is no lower than ``pelvis_min_height_m`` (None: as low as his) [m], the ankles then where his
    are over the ground (the legs stretched instead of the feet lifted). ``ankle_shift_world`` (3,) [m] moves both
    ankles' targets from where his are, the pelvis staying (:func:`standing_start_shift`)."""
    if scale is None:
        scale = CHAR_LEG_LENGTH_M / analysis.leg_m  # Eq. 9
    q_root = analysis.root_quat_wxyz
    R_root = rot.matrix_from_quat(q_root)
    p_h = operator_pelvis_world(s.pos, from_hip_joints)
    ankles = {side: s.pos[f"ANKLE_{side.upper()}"] for side in ("left", "right")}
    ankle_h_z = min(a[2] for a in ankles.values())
    pelvis = np.array([scale * p_h[0], scale * p_h[1], ANKLE_HEIGHT_M + scale * (p_h[2] - ankle_h_z)])  # Eq. 9
    raised = (pelvis_min_height_m is not None
              and below_crouch_floor(pelvis[2], pelvis_min_height_m, s.pos["NECK"] - p_h))
    if raised:
        pelvis[2] = pelvis_min_height_m  # as the motion stage's floor under his crouch
    local: dict[str, np.ndarray] = {}
    hinge: dict[str, float] = {}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        hip = pelvis + R_root @ np.array([0.0, sign * HIP_HALF_WIDTH_M, 0.0])
        target = pelvis + scale * (ankles[side] - p_h)
        if raised:
            target[2] = ANKLE_HEIGHT_M + scale * (ankles[side][2] - ankle_h_z)  # where his is above the ground
        if ankle_shift_world is not None:
            target = target + ankle_shift_world
        target[2] = max(target[2], ANKLE_HEIGHT_M)
        N = analysis.features.N_l if side == "left" else analysis.features.N_r
        ik = solve_leg(hip, target, THIGH_LENGTH_M, SHANK_LENGTH_M, N)
        local[f"{side}_hip"] = rot.multiply(rot.conjugate(q_root), ik.thigh_quat_wxyz)
        hinge[f"{side}_knee"] = ik.knee_angle_rad
        q_foot = rot.quat_from_yaw(rot.twist_angle(s.quat[f"ANKLE_{side.upper()}"], _UP))  # flat (Sec. 5.3)
        local[f"{side}_ankle"] = rot.multiply(rot.conjugate(ik.shank_quat_wxyz), q_foot)
    map_upper_body(analysis.upper_local_wxyz, local, hinge)
    return pelvis, q_root, joint_targets(local, hinge)


def initial_state(s0: OperatorSample, a0: OperatorAnalysis, s1: OperatorSample, a1: OperatorAnalysis,
                  from_hip_joints: bool = False, pelvis_min_height_m: float | None = None,
                  ankle_shift_world: np.ndarray | None = None) -> InitialState:
    """The character's state at ``s0``, with velocities from the forward difference to ``s1`` (later); his pelvis,
    the pelvis's floor and the ankles' shift as :func:`retargeted_pose` takes them (the same shift in both poses)."""
    dt = s1.time_s - s0.time_s
    if not dt > 0:
        raise ValueError("initial_state needs a second sample later than the first")
    # One scale for both poses: positions are scaled from the world origin, metres away, and the sensor noise on the
    # operator's leg length (Eq. 1) changes the scale from sample to sample by about 1 %, which alone would add some
    # 0.3 m/s to a forward difference over a 16 Hz frame.
    scale = CHAR_LEG_LENGTH_M / a0.leg_m
    p0, q0, j0 = retargeted_pose(s0, a0, scale, from_hip_joints, pelvis_min_height_m, ankle_shift_world)
    p1, q1, j1 = retargeted_pose(s1, a1, scale, from_hip_joints, pelvis_min_height_m, ankle_shift_world)
    q1 = rot.align_sign(q1, q0)
    ang_root = rot.rotvec_from_quat(rot.multiply(q1, rot.conjugate(q0))) / dt
    joint_vel = np.zeros((len(JOINTS), 3))
    for k in _BALL:
        joint_vel[k] = rot.rotvec_from_quat(rot.multiply(rot.conjugate(j0[k]), rot.align_sign(j1[k], j0[k]))) / dt
    joint_vel[_HINGE, 0] = (j1[_HINGE, 0] - j0[_HINGE, 0]) / dt
    pelvis = operator_pelvis_world(s0.pos, from_hip_joints)
    origin = np.array([pelvis[0] - p0[0], pelvis[1] - p0[1], 0.0])  # at the operator's pelvis
    return InitialState(p0 + origin, q0, j0, (p1 - p0) / dt, ang_root, joint_vel)


def start_velocity_share(root_lin_vel_world: np.ndarray, max_speed_mps: float | None) -> float:
    """The share [0, 1] of the initial velocities that starts the character with its root's horizontal speed (of
    ``root_lin_vel_world``, (3,) [m/s]) at most ``max_speed_mps`` [m/s] (None: 1, the clip's velocities as they are).
    One share for the root and every joint: the pose's motion is slowed as a whole, not reshaped."""
    if max_speed_mps is None:
        return 1.0
    speed = float(np.hypot(root_lin_vel_world[0], root_lin_vel_world[1]))
    return 1.0 if speed <= max_speed_mps else max_speed_mps / speed


def standing_start_shift(com_world: np.ndarray, com_vel_world: np.ndarray, gravity_mps2: float,
                         soles_xy: list[list[Point]]) -> np.ndarray | None:
    """Where a standing start puts the character's capture point ξ = c + ċ / ω (recovery_step.capture_point, Eq. 21's
    pendulum; COM ``com_world`` and ``com_vel_world``, world [m, m/s]) outside the support polygon of
    its soles ``soles_xy`` (each its corners' world horizontal positions, shrunk as MotionConfig.
    standing_start_sole_share says): the horizontal shift (3,) [m] of both ankles that puts ξ back on that polygon,
    None where it is within.

    His pose is mapped pelvis to ankles, and his centre of mass lies otherwise over his feet than the character's over
    its own (other proportions, another mass distribution, a marker-based skeleton's ankle): a person standing with
    his weight over the balls of his feet started the character with its capture point at the front edge of what the
    capture bound allows, the COM drifting over it, its centre of pressure at the soles' edge unable to hold it back,
    and a step of its own before his first (docs/decisions.md, "A standing start over the toes"). The feet are moved,
    not the pelvis: his pelvis stays where he is, and a standing body's feet are set down under its weight."""
    xi, _ = capture_point(com_world, com_vel_world, gravity_mps2)
    distance, (nx, ny) = outside_distance_points((float(xi[0]), float(xi[1])),
                                                 convex_hull_points([p for sole in soles_xy for p in sole]))
    if distance <= 0.0:
        return None
    return np.array([xi[0] - nx, xi[1] - ny, 0.0])

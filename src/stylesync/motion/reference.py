"""The reference pose: what the motion optimisation hands to the balance and synchronisation controller."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync.motion.stance_fsm import Stance
from stylesync.motion.style_features import StyleFeatures


@dataclass
class LipmMap:
    """Inputs of Eq. 23 for the current single stance."""

    d_a_human: np.ndarray  # (3,) operator COM minus stance ankle, horizontal [m]
    h_human_m: float  # operator COM height above the stance ankle [m]
    d_a_char: np.ndarray  # (3,) character COM minus stance ankle, horizontal [m]
    h_char_m: float


@dataclass
class ReferencePose:
    """The targets of one control tick, all in the character's terms (world frame): what the controller tracks."""

    time_s: float
    joint_pos: np.ndarray  # (n_joints, 4) desired local rotations (model axes), hinge angle in column 0
    root_quat_wxyz: np.ndarray  # desired canonical pelvis orientation (level, heading H)
    pelvis_world: np.ndarray  # desired pelvis origin (Eq. 9-10) [m]
    com_world: np.ndarray  # desired character COM [m]
    com_vel_world: np.ndarray  # [m/s]
    character_stance: Stance  # the feet the character is to stand on
    stance_weight: dict[str, float]
    ankle_world: dict[str, np.ndarray]  # current character ankle joints [m]
    lipm: LipmMap | None
    # The swing foot is to be pressed onto the ground: a late contact (Sec. 5.1) holds the reference until it touches
    press_swing_foot: bool
    # The operator's wrists relative to his pelvis (world axes), scaled, placed at the character's pelvis [m]
    hand_world: dict[str, np.ndarray] | None = None
    # The swing ankle's target during a step the character takes on its own (recovery_step.py); below the ground once
    # its landing is due [m]
    recovery_ankle_world: dict[str, np.ndarray] | None = None
    # Its velocity along the step's swing profile, the landing held where it is this tick (recovery_step.py) [m/s]
    recovery_ankle_vel_world: dict[str, np.ndarray] | None = None
    # That step is taken while the operator stands (his capture point within his soles): a step that is to stop the
    # body, not to go anywhere
    recovery_while_he_stands: bool = False
    # The pelvis target's vertical speed: the operator's pelvis's, scaled (Eq. 9), smoothed; 0 while the target is
    # lowered for a foot to reach the ground [m/s]
    pelvis_vel_z_mps: float = 0.0
    # How fast the operator goes somewhere over the ground: the lower of his way's average speed (operator_way.py)
    # and his COM's horizontal speed now, scaled (a gait, not a stand, a sway or a jump in place) [m/s]
    his_way_speed_mps: float = 0.0
    # He and the character stand still: he on both feet, his feet at rest and his COM's horizontal speed now, scaled,
    # below 5 cm/s; the character's COM below 0.25 m/s and no weight shift of its own for a step to where he stands
    both_stand_still: bool = False


@dataclass(frozen=True)
class MotionReading:
    """What the motion stage read from the operator and decided at one tick, besides the targets: for the run's
    log, the session file and the viewer (``MotionOptimizer.reading``)."""

    operator_stance: Stance
    operator_features: StyleFeatures
    held: bool  # the reference is held waiting for a late contact (Sec. 5.1)
    scale: float  # character / operator size ratio (h_C / h_H of Eq. 9)
    step_bound_exceeded: bool  # the swing foot's target was cut to the step-length bound (Eq. 28)

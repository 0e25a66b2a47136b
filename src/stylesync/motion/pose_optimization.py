"""Style-based pose optimisation (Sec. 5.3) and the motion-optimisation stage that wires Sec. 5 together.

Per control tick, from the smoothed operator sample and the character's current state:
1. stance FSMs (Sec. 5.1) and style features (Sec. 5.2);
2. lower-body retargeting on the character's *current* feet: pelvis height by Eq. 9 and horizontal position by
   Eq. 10, read (see the notes) as keeping the operator's *fraction* of the way between the ankles per axis of the
   heading frame; where the ankles are less than ``_MIN_AXIS_SPREAD_M`` apart along an axis the fraction is
   undefined and the operator's offset from the ankle midpoint, scaled, is used instead. In single stance the
   pelvis keeps the operator's scaled offset from the stance ankle. The desired COM (Eq. 19) is mapped the same
   way;
3. leg IK in the motion plane N of each leg (unique 2D solution), stance feet where they are, the swing foot
   where the operator's is (scaled, relative to his stance foot, corrected towards the character's capture point;
   or relative to the pelvis), its step length bounded by Eq. 28;
4. feet flat, heading from the operator's foot (twist T) for the swing foot, current heading for a planted foot;
5. balance strategy (Sec. 5.4): level root with heading H, Eq. 11 on the stance hips, Eq. 12 on the swing hip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stylesync import rotations as rot
from stylesync.config import MotionConfig
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    FOOT_CENTER_AHEAD_OF_ANKLE_M,
    FOOT_LENGTH_M,
    FOOT_WIDTH_M,
    HIP_HALF_WIDTH_M,
    JOINT_NAMES,
    JOINTS,
    LEG_LINKS,
    LINK_NAMES,
    OTHER_SIDE,
    SHANK_LENGTH_M,
    THIGH_LENGTH_M,
    JointKind,
    batch_model_quat_from_canonical,
    canonical_quat_from_model,
)
from stylesync.model.sole import sole_corner_points, sole_outside_m, sole_points_xy, sole_within_m
from stylesync.model.state import CharacterState, MassProperties
from stylesync.motion.balance_strategy import stance_hip_blend, swing_hip_feedback
from stylesync.motion.bounds import BoundsMonitor, step_length_bound_m
from stylesync.motion.capture_bound import bounded_com_target, gait_capture_margin_m, landing_catch_region
from stylesync.motion.double_stance_momentum import GAIT_AXIS_DEG, kept_com_velocity, moves_between_feet
from stylesync.motion.his_rise import HisRise
from stylesync.motion.leg_ik import solve_leg
from stylesync.motion.operator_analysis import UPPER_JOINTS, OperatorAnalysis, analyse_operator, upper_local
from stylesync.motion.operator_way import OperatorWay
from stylesync.motion.path_feedback import (
    PathReference,
    bounded_xy,
    pull_share_after_steps,
    pull_share_at_speed,
)
from stylesync.motion.recovery_step import (
    RecoveryStepper,
    WalkOn,
    beyond_sole_towards_m,
    capture_point,
    capture_point_after,
    operator_stands,
    out_of_reach_after_wait,
    soles_on_ground,
    stands_on,
    support_outside_along,
    support_outside_m,
)
from stylesync.motion.reference import LipmMap, MotionReading, ReferencePose
from stylesync.motion.rest_step import REST_FOOT_MIN_WEIGHT, WEIGHT_OVER_SOLE_M, rest_step_plan
from stylesync.motion.stance_fsm import (
    CharacterStanceFsm,
    OperatorStanceFsm,
    Stance,
    stance_weights,
    swing_side,
)
from stylesync.processing.body_parameters import leg_length_m, operator_pelvis_world
from stylesync.processing.interpolation import smooth_step
from stylesync.processing.joint_map import hinge_angle
from stylesync.processing.operator_processing import OperatorSample

_MIN_AXIS_SPREAD_M = 0.08
_UP = np.array([0.0, 0.0, 1.0])
LATE_CONTACT_PRESS_M = 0.02  # a swing foot held for a late contact is aimed this far below the ground [m]
LANDING_REACH = 0.97  # hip-ankle distance, as a fraction of the leg's length, at which a landing foot is aimed
OPERATOR_SWING_S = 0.4  # the operator's swing time before one has been seen [s]
OPERATOR_DOUBLE_STANCE_S = 0.2  # the operator's double-stance time before one has been seen [s]
SWING_BLEND_S = 0.1  # time constant over which a swing foot moves from its lift-off point onto its target [s]
FREE_SWING_BLEND_S = 0.1  # time over which a swing foot goes over to following his foot, or back [s]
ANCHOR_BLEND_S = 0.15  # time constant over which a stance change's jump of the retargeting anchor is taken up
_SCALE_SMOOTHING = 0.02  # per tick, exponential average of the operator's leg length
_BALL_JOINTS = [k for k, j in enumerate(JOINTS) if j.kind is JointKind.BALL]
_HINGE_JOINTS = [k for k, j in enumerate(JOINTS) if j.kind is not JointKind.BALL]
_VELOCITY_SMOOTHING = 0.2  # per tick, exponential average of the desired COM velocity
# He stands while on both feet with his COM's scaled speed, now and averaged over his way (operator_way.py), below
# this; the targets then follow the anchored ones with MotionConfig.reference_follows_standing_s once they are within
# _STANDING_LEAD_M of them (a walk's lead is first taken up at the walking time constant) [m/s], [m]
_STANDING_SPEED_MPS = 0.05
_STANDING_FOR_S = 1.0  # ... and has stood so for this long (not a pause between two jumps or in a dance) [s]
_STANDING_LEAD_M = 0.005
# His feet are at rest (steps to where he stands, rest_step.py) below this speed over the ground, scaled [m/s], smoothed
# over this time [s]: standing, the sensor's noise moves them at most 0.05 m/s; a foot he slides or turns in a dance
# goes 0.4-1.2 m/s
_FEET_STILL_MPS = 0.1
_FEET_SPEED_SMOOTHING_S = 0.1
# The character's COM speed below which it stands, for ReferencePose.both_stand_still [m/s]: standing, it sways at up to
# 0.17 m/s; a body that brakes from a run on a long last step still travels at 0.3-0.6 m/s over its front foot, and
# loading its rear sole then (WholeBodyConfig.standing_sole_min_load_share) folded its front leg (CMU-dev 02_03).
# Between the two (docs/decisions.md, "The standing soles' load by default").
CHARACTER_STANDS_MPS = 0.25
_GAIT_AXIS_COS = math.cos(math.radians(GAIT_AXIS_DEG))
_SIDE_UP = {"left": "LEFT", "right": "RIGHT"}
# A crouch: his trunk (pelvis to neck) within this of the vertical. Lying, crawling, rolling, it is further [deg]
CROUCH_TRUNK_MAX_DEG = 60.0
_CROUCH_TRUNK_COS = math.cos(math.radians(CROUCH_TRUNK_MAX_DEG))
_LINK = {n: i for i, n in enumerate(LINK_NAMES)}
_ROOT_LINK = _LINK["root"]
CHAR_LEG_LENGTH_M = THIGH_LENGTH_M + SHANK_LENGTH_M
_LANDING_REACH_M = LANDING_REACH * CHAR_LEG_LENGTH_M  # hip-ankle distance at which a landing foot is aimed [m]
# How fast the operator's floor (the lowest his ankles have been) rises towards his lower ankle: faster than a
# climb of stairs (a 0.17 m step in about 0.6 s), slower than a leap's feet (the built-in spin's rise at 4-6 m/s) [m/s]
OPERATOR_FLOOR_RISE_MPS = 0.5
OPERATOR_VELOCITY_SETTLE_S = 0.2  # the operator's filtered COM velocity is taken as settled from then on [s]
HEEL_AHEAD_OF_ANKLE_M = FOOT_CENTER_AHEAD_OF_ANKLE_M - FOOT_LENGTH_M / 2  # < 0: the heel is behind the ankle [m]


def pelvis_offset_m(offset_m: float, his_speed_mps: float, full_speed_mps: float, start_speed_mps: float = 0.0
                    ) -> float:
    """The pelvis target's offset from his (MotionConfig.pelvis_height_offset_m) [m] at his scaled horizontal COM
    speed ``his_speed_mps`` [m/s]: none up to ``start_speed_mps`` (standing still, none), in full from
    ``full_speed_mps`` on, in proportion between."""
    if his_speed_mps <= start_speed_mps:
        return 0.0
    return offset_m * min((his_speed_mps - start_speed_mps) / (full_speed_mps - start_speed_mps), 1.0)


def _heading_world(tick: _Tick) -> np.ndarray:
    """(3,) the forward axis of his heading (the reference root's), horizontal, unit, world frame."""
    heading = np.array([tick.R_root_d[0, 0], tick.R_root_d[1, 0], 0.0])
    return heading / max(float(np.linalg.norm(heading)), 1e-9)


def _heading_frame_fraction(p_h, al_h, ar_h, al_c, ar_c, scale: float, R: np.ndarray,
                            rear_to_front: bool = False) -> np.ndarray:
    """Eq. 10 (fraction reading) in the heading frame (world rotation ``R``), horizontal components only.

    Along an axis where the feet are close together the fraction is ill-defined; there the operator's offset from
    the ankle midpoint, scaled, is used. The two are blended by how far apart the feet are (the lesser of the
    operator's and the character's spread, from _MIN_AXIS_SPREAD_M / 2 to _MIN_AXIS_SPREAD_M * 1.5), so that the
    target does not jump when a swing foot passes the stance foot. With ``rear_to_front`` the fraction goes from his
    rear foot to his front one along the heading (x), and so it does on the character's feet: where the character's
    own step has put its other foot ahead (his left foot ahead of his right, its right ahead of its left), his COM over
    his front foot is its COM over its front foot, not over its left one, now behind. The order can only change
    where one of the spreads passes zero, where the blend is the midpoint's offset: the target does not jump.
    """
    ph, lh, rh, lc, rc = (R.T @ np.array([p_h, al_h, ar_h, al_c, ar_c]).T).T.tolist()  # heading-frame coordinates
    out = [0.0, 0.0, 0.0]
    for ax in (0, 1):
        spread_h, spread_c = rh[ax] - lh[ax], rc[ax] - lc[ax]
        offset = 0.5 * (lc[ax] + rc[ax]) + scale * (ph[ax] - 0.5 * (lh[ax] + rh[ax]))
        w = min(max(min(abs(spread_h), abs(spread_c)) / _MIN_AXIS_SPREAD_M - 0.5, 0.0), 1.0)
        near = lc[ax]
        if rear_to_front and ax == 0 and spread_h * spread_c < 0.0:
            near, spread_c = rc[ax], -spread_c
        out[ax] = offset
        if w > 0.0:
            out[ax] += w * (near + spread_c * (ph[ax] - lh[ax]) / spread_h - offset)
    return R @ np.array(out)


def _inward_m(point_world: np.ndarray, ankle_world: np.ndarray, foot_yaw_rad: float, side: str) -> float:
    """How far a point is from the ``side`` ankle towards the other foot, across that foot (its frame's y) [m]."""
    inward = -1.0 if side == "left" else 1.0
    d = np.asarray(point_world, dtype=float)[:2] - np.asarray(ankle_world, dtype=float)[:2]
    return inward * float(-np.sin(foot_yaw_rad) * d[0] + np.cos(foot_yaw_rad) * d[1])


def map_upper_body(upper_local_wxyz: np.ndarray, local: dict[str, np.ndarray], hinge: dict[str, float]) -> None:
    """In place: the joint map's upper-body rotations (UPPER_JOINTS order) as ball-joint local rotations and elbow
    hinge angles [rad]."""
    for j, q in zip(UPPER_JOINTS, upper_local_wxyz, strict=True):
        if j.endswith("elbow"):
            hinge[j] = hinge_angle(q, j)
        else:
            local[j] = q


def joint_targets(local: dict[str, np.ndarray], hinge: dict[str, float]) -> np.ndarray:
    """(n_joints, 4) in the character's joint layout: ball joints' canonical local rotations as model-frame
    quaternions, hinge angles [rad] in column 0."""
    joint_pos = np.zeros((len(JOINTS), 4))
    joint_pos[_BALL_JOINTS] = batch_model_quat_from_canonical(np.array([local[JOINTS[k].name] for k in _BALL_JOINTS]))
    for k in _HINGE_JOINTS:
        joint_pos[k, 0] = hinge[JOINTS[k].name]
    return joint_pos


_MIRROR_Y = np.array([1.0, -1.0, 1.0])  # a heading-frame offset to the other side


class _SmoothedRate:
    """Rate of change of a sampled vector: finite difference, exponentially averaged (_VELOCITY_SMOOTHING)."""

    def __init__(self, dt_s: float):
        self.dt_s = dt_s
        self._prev: np.ndarray | None = None
        self._rate = np.zeros(3)

    @property
    def rate(self) -> np.ndarray:
        """The current estimate (3,)."""
        return self._rate

    def prime(self, rate: np.ndarray) -> None:
        """Start from this rate (3,) instead of rest (a recording started mid-motion)."""
        self._rate = np.array(rate, dtype=float)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if self._prev is not None:
            self._rate += _VELOCITY_SMOOTHING * ((x - self._prev) / self.dt_s - self._rate)
        self._prev = np.array(x, dtype=float)
        return self._rate.copy()


@dataclass
class _Tick:
    """What the steps of one motion tick hand each other (world frame, metres; ``_h`` the operator, ``_c`` the
    character, ``_d`` a target)."""

    sample: OperatorSample  # this tick's operator sample
    s: OperatorSample  # the sample the reference follows (the held one during a late contact)
    analysis: OperatorAnalysis
    op_state: Stance
    ch_state: Stance
    contact: dict[str, bool]
    op_leg_m: float = 0.0
    scale: float = 1.0  # h_C / h_H, Eq. 9
    q_root_d: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    R_root_d: np.ndarray = field(default_factory=lambda: np.eye(3))
    a_h: dict[str, np.ndarray] = field(default_factory=dict)  # operator ankles
    a_c: dict[str, np.ndarray] = field(default_factory=dict)  # character ankles
    p_h: np.ndarray = field(default_factory=lambda: np.zeros(3))  # operator pelvis
    com_h: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_c: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_vel_c: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_vel_h: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ankle_h_z: float = 0.0
    pelvis_d: np.ndarray = field(default_factory=lambda: np.zeros(3))
    pelvis_vel_z: float = 0.0  # the pelvis target's vertical speed [m/s]
    pelvis_offset_m: float = 0.0  # the pelvis target less his, scaled (MotionConfig.pelvis_height_offset_m) [m]
    com_d: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_vel_d: np.ndarray = field(default_factory=lambda: np.zeros(3))
    weights: dict[str, float] = field(default_factory=dict)  # stance weights
    swing: str | None = None
    targets: dict[str, np.ndarray] = field(default_factory=dict)  # ankle targets
    foot_yaw: dict[str, float] = field(default_factory=dict)
    step_exceeded: bool = False
    he_stands: bool = False  # he has stood still for a while (MotionOptimizer._he_stands)
    his_feet_still: bool = False  # his feet at rest (MotionOptimizer._his_feet_still)
    swing_landing_xy: np.ndarray | None = None  # where the swing ankle is planned to land (his swing) [m]
    # The operator's capture point and whether it is within the soles he stands on, computed once a tick
    xi_h: np.ndarray | None = None
    stands: dict[tuple[str, ...], bool] = field(default_factory=dict)


def _sole_within_m(state: CharacterState, side: str, gap_m: float) -> bool:
    """Whether the lowest corner of the sole on ``side`` is within ``gap_m`` of the ground (model/sole.py)."""
    ankle = _LINK[f"{side}_ankle"]
    return sole_within_m(state.link_origin_world[ankle], state.link_quat_wxyz[ankle], gap_m)


def _trunk_upright(pelvis_to_neck: np.ndarray) -> bool:
    """Whether his trunk (the (3,) pelvis-to-neck vector, world, z up) is within CROUCH_TRUNK_MAX_DEG of vertical."""
    return bool(pelvis_to_neck[2] > _CROUCH_TRUNK_COS * np.linalg.norm(pelvis_to_neck))


def below_crouch_floor(pelvis_z_m: float, floor_m: float, pelvis_to_neck: np.ndarray) -> bool:
    """Whether a pelvis target at ``pelvis_z_m`` [m] is held up by the crouch's floor ``floor_m``
    (MotionConfig.pelvis_min_height_m) [m]: below it while his trunk (pelvis to neck, world) is upright. The motion
    stage's pelvis target and the start in his first pose (initial_state.py) both keep it."""
    return pelvis_z_m < floor_m and _trunk_upright(pelvis_to_neck)


class MotionOptimizer:
    def __init__(self, cfg: MotionConfig, control_hz: float, bounds: BoundsMonitor | None = None,
                 gravity_mps2: float = 9.8):
        self.cfg = cfg
        self.g = gravity_mps2
        self.dt_s = 1.0 / control_hz
        # A landing foot lowers the pelvis target to at least this height above the foot's target [m]
        self._landing_pelvis_floor_m = cfg.landing_pelvis_floor_share * _LANDING_REACH_M
        # The hip-to-ankle distance the pelvis target keeps within above a planted stance foot [m]
        share = cfg.pelvis_stance_reach_share
        self._stance_reach_m = None if share is None else share * CHAR_LEG_LENGTH_M
        # How far from its hip, horizontally, a swing foot can land with the pelvis at that floor [m]
        self._swing_reach_m = math.sqrt(max(_LANDING_REACH_M ** 2 - self._landing_pelvis_floor_m ** 2, 0.0))
        self.op_fsm = OperatorStanceFsm(cfg.stance_height_threshold_m, cfg.stance_hysteresis_m)
        self.char_fsm = CharacterStanceFsm(cfg.late_contact_timeout_s, cfg.min_swing_s,
                                           cfg.liftoff_needs_other_foot_down)
        self._op_leg_m: float | None = None
        self._rear_foot_bearing: str | None = None  # the side of his raised foot read as bearing weight, last tick
        self._held: OperatorSample | None = None
        self._com_d_rate = _SmoothedRate(self.dt_s)  # desired COM velocity [m/s]
        self._com_h_rate = _SmoothedRate(self.dt_s)  # operator COM velocity [m/s]
        self._pelvis_h_rate = _SmoothedRate(self.dt_s)  # operator pelvis velocity [m/s]
        self._ankle_h_rate = {side: _SmoothedRate(self.dt_s) for side in _SIDE_UP}  # operator ankle velocities [m/s]
        self._his_rise = HisRise() if cfg.rise_begun_on_both_feet else None  # his_rise.py
        self.way = OperatorWay(cfg.operator_way_time_s, self.dt_s)  # his way over the ground (operator_way.py)
        # His way in his own heading frame (x forwards; its velocity_world holds heading-frame axes), kept up when
        # rear_foot_stepping_way_mps reads it (_rear_foot_bears_weight)
        self._way_heading = OperatorWay(cfg.operator_way_time_s, self.dt_s)
        # only a gait's speed, a walk-on along his way or the path's pull reads it: otherwise it is not kept up each
        # tick
        self._tracks_way = (cfg.gait_min_way_speed_mps is not None or cfg.recovery_walk_on_his_way
                            or cfg.path_target_share > 0.0)
        self.bounds = bounds if bounds is not None else BoundsMonitor()
        self._anchor_stance: Stance | None = None
        self._anchor_offset = np.zeros((2, 2))  # (pelvis, COM) x (x, y) [m]
        self._anchor_decay = np.exp(-self.dt_s / ANCHOR_BLEND_S)  # per tick
        self._swing_decay = np.exp(-self.dt_s / SWING_BLEND_S)  # per tick
        self._last_xy: np.ndarray | None = None
        self._op_ankle_floor_z: float | None = None  # the operator's floor under his ankles [m]
        self._planned_landing_xy: np.ndarray | None = None  # his swing's landing as the last tick planned it [m]
        self._op_ankle_ground_z: dict[str, float] = {}  # per side, his ankle's height when it last could bear weight
        self._hold_velocity: np.ndarray | None = None  # the desired COM velocity a late-contact hold began with
        self._hold_shift = np.zeros(2)  # the held targets' travel since the hold began [m]
        self._ref_xy: np.ndarray | None = None  # (pelvis, COM) x (x, y) targets that follow the operator [m]
        # since when he has stood (_STANDING_SPEED_MPS; before the start if he stands from it) [s]
        self._stands_since_s: float | None = -math.inf
        self._swing: str | None = None
        self._feet_by_own_step = False  # the character's last step was its own (a recovery step), not one of his
        self.path = PathReference(cfg.path_feedback_share, cfg.path_feedback_max_m, cfg.path_target_share,
                                  cfg.path_target_max_m)  # path_feedback.py
        self._swing_offset = np.zeros(2)  # lift-off foot position minus the first swing target, decaying [m]
        self._free_share = 0.0  # how much the swing foot follows his (_free_swing_share) [0, 1]
        self._swing_t0_s = 0.0  # when the character's current swing began [s]
        self._liftoff_xy = np.zeros(2)  # where the current swing's foot lifted off [m]
        # Per side, the offset of the operator's foot from his capture point when it last came down, scaled, in his
        # heading frame (x forwards, y to the left) [m]; the side he has just landed, to be recorded this tick
        self._his_landing: dict[str, np.ndarray] = {}
        self._his_landed_side: str | None = None
        self._aim_at_his_landing = cfg.swing_landing == "his_last_landing"  # MotionConfig.swing_landing
        self._planted_yaw: dict[str, float] = {}  # each planted foot's yaw when it last pressed the ground [rad]
        self._last_pelvis_z: float | None = None  # the last tick's pelvis target (landing_pelvis_descent_mps) [m]
        self._op_swing_s = OPERATOR_SWING_S  # the operator's swing time, averaged over his swings [s]
        self._op_state: Stance | None = None
        self._op_state_t0_s = 0.0
        self._his_single_stance_s = -math.inf  # the last tick the operator stood on one foot [s]
        self._pull_along = 0.0  # how much of the last operator_way_time_s he went along his way [-]
        self._pull_along_share = min(self.dt_s / cfg.operator_way_time_s, 1.0)
        self._op_last_ds_s = 0.0
        self.recovery = RecoveryStepper(cfg, CHAR_LEG_LENGTH_M, gravity_mps2)
        self._operator_stands_since_s: float | None = None
        # the operator's double-stance time, averaged over his double stances (of a walk: each counted 0.05-1 s) [s]
        self._op_ds_s = OPERATOR_DOUBLE_STANCE_S
        self._outside_since_s: float | None = None  # the character's capture point left its double support then [s]
        self._stopping_capture_side: str | None = None  # the swing whose landing _stopping_landing moved last tick
        # Steps to where he stands (rest_step.py): the foot the weight is on (shifting to it, or standing on it while
        # the other steps), decided each tick; the COM target's offset that moves the weight there, and that target
        self._rest_stance: str | None = None
        self._rest_offset_xy = np.zeros(2)
        self._rest_com_xy: np.ndarray | None = None
        self.rest_steps = 0  # steps taken to where he stands
        # the last such step: its foot, where it lifted off and where it was to land [m]
        self._rest_last: tuple[str, np.ndarray, np.ndarray] | None = None
        self._his_feet_speed_mps = 0.0  # his feet's fastest speed over the ground, scaled, smoothed [m/s]
        self._his_feet_last: tuple[float, float, float, float] | None = None  # his feet over the ground, last tick [m]
        self._sole_bound = sole_corner_points(cfg.capture_bound_sole_share)  # shrunk for capture_bound.py [m]
        self.reading: MotionReading | None = None  # the last tick's reading of the operator, besides the targets

    def _last_scale(self) -> float | None:
        """The character / operator size ratio of the last tick (Eq. 9, from his smoothed leg length); None before
        his leg is known."""
        return CHAR_LEG_LENGTH_M / self._op_leg_m if self._op_leg_m else None

    def prime_rates(self, com_vel_h_world: np.ndarray, com_vel_d_world: np.ndarray) -> None:
        """Start the operator's COM velocity and the desired COM velocity (Eq. 19) from these [m/s] instead of
        rest: a character started with a recording's velocities (OperatorConfig.start_with_clip_velocity)."""
        self._com_h_rate.prime(com_vel_h_world)
        self._com_d_rate.prime(com_vel_d_world)
        self.way.prime(com_vel_d_world)

    def update(self, sample: OperatorSample, state: CharacterState, mass: MassProperties,
               analysis: OperatorAnalysis | None = None) -> ReferencePose:
        """The reference pose of one control tick, in the steps of the module's notes. ``analysis``:
        :func:`analyse_operator` of ``sample`` if it was computed ahead (prefetch.py); None computes it here."""
        if analysis is None:
            analysis = analyse_operator(sample)
        tick = self._track_stance(sample, state, analysis, mass)
        self._retarget_lower_body(tick, state, mass)
        self._plan_feet(tick, state, mass)
        local, hinge = self._solve_legs(tick, state)
        self._map_upper_body(tick, local, hinge)
        return self._reference(tick, state, local, hinge)

    # ---- 1. stance tracking (Sec. 5.1) ---------------------------------------------------------------------
    def _can_lift(self, sample: OperatorSample, state: CharacterState, mass: MassProperties
                  ) -> tuple[dict[str, bool] | None, set[str]]:
        """Weight shift before a lift-off: per foot, whether the character may lift it now (None: no such test now),
        and the feet held down by the first test below (``liftoff_behind_waits``: those wait however long).

        * Any lift-off (``liftoff_capture_behind_m``): a foot that bears weight may not while the character's
          capture point is further than that outside its other sole towards it
          (recovery_step.beyond_sole_towards_m). On the other foot alone, the body would fall back onto the lifted
          one: a start at rest mid-stride, or a character that lags its operator, lifts the rear foot while its
          capture point is still behind the front heel.
        * A lift-off after standing: a foot may not when the operator lifts it after a double stance of at least
          ``liftoff_after_stand_s`` (a step or a kick from standing, not a walk's double stance) with his capture
          point over his other sole, sideways (within ``liftoff_margin_m`` of its inner edge, his sole the
          character's scaled to him), while the character's capture point is further than that inwards of its own
          other sole; where his is over or beyond his stance ankle (his weight on that foot: a kick, a pose on one
          leg), while the character's is further inwards of its stance ankle than ``liftoff_shift_tolerance_m``; and
          wherever his is over his stance sole, while the character's is further outwards of its stance ankle than
          ``liftoff_shift_outward_m``."""
        cfg = self.cfg
        if cfg.liftoff_weight_shift_s <= 0.0:
            return None, set()
        stood_s = (state.time_s - self._op_state_t0_s) if self._op_state is Stance.DS else self._op_last_ds_s
        after_stand = stood_s >= cfg.liftoff_after_stand_s
        behind_limit_m = cfg.liftoff_capture_behind_m
        if behind_limit_m is None and not after_stand:
            return None, set()
        xi, _ = capture_point(mass.com(state), mass.com_velocity(state), self.g)
        pressing = state.feet_pressing()
        if after_stand:
            scale = self._last_scale() or 1.0
            h_h = max(sample.com_world[2] - min(sample.pos["ANKLE_LEFT"][2], sample.pos["ANKLE_RIGHT"][2]), 0.1)
            xi_h = sample.com_world + self._com_h_rate.rate * np.sqrt(h_h / self.g)
            edge = FOOT_WIDTH_M / 2 + cfg.liftoff_margin_m
        can, behind = {}, set()
        for side in ("left", "right"):
            stance = OTHER_SIDE[side]
            ankle = state.link_origin_world[_LINK[f"{stance}_ankle"]]
            foot_q = state.link_quat_wxyz[_LINK[f"{stance}_ankle"]]
            may = not (behind_limit_m is not None and pressing[side] and beyond_sole_towards_m(
                xi, ankle, foot_q, state.link_origin_world[_LINK[f"{side}_ankle"]]) > behind_limit_m)
            if not may:
                behind.add(side)
            if after_stand:
                ankle_h = sample.pos[f"ANKLE_{_SIDE_UP[stance]}"]
                yaw_h = rot.twist_angle(sample.quat[f"ANKLE_{_SIDE_UP[stance]}"], _UP)
                inward_h = scale * _inward_m(xi_h, ankle_h, yaw_h, stance)
                if inward_h <= edge:  # he stands on that foot
                    # Over the stance ankle where his weight is over his (a kick, a pose on one leg); otherwise
                    # within the margin of the sole's inner edge
                    limit = (edge if cfg.liftoff_shift_tolerance_m is None or inward_h > 0.0
                             else cfg.liftoff_shift_tolerance_m)
                    inward = _inward_m(xi, ankle, rot.twist_angle(foot_q, _UP), stance)
                    may = may and inward <= limit
                    if cfg.liftoff_shift_outward_m is not None:  # nor beyond the stance ankle, outwards
                        may = may and inward >= -cfg.liftoff_shift_outward_m
            can[side] = may
        return can, behind

    def _feet_down(self, state: CharacterState) -> dict[str, bool]:
        """Per side, whether the foot is on the ground: it presses it (``CharacterState.feet_pressing``), or it is a
        recovery step's foot past its horizontal travel whose sole's lowest corner is within
        ``recovery_landing_gap_m`` of the ground (it has landed, if on a corner); with ``own_step_scuff_before_due``
        a recovery step's foot that presses the ground before its landing is due, more than a foot's length short of
        it, is not on it (a scuff)."""
        contact = state.feet_pressing()
        gap, step = self.cfg.recovery_landing_gap_m, self.recovery.step
        if (self.cfg.own_step_scuff_before_due and step is not None and self.char_fsm.recovery_step
                and contact[step.side] and not self.recovery.landing_due(state.time_s)):
            ankle = state.link_origin_world[_LINK[f"{step.side}_ankle"]]
            short_m = math.hypot(float(step.landing_world[0] - ankle[0]), float(step.landing_world[1] - ankle[1]))
            if short_m > FOOT_LENGTH_M:  # more than a foot's length short of its landing
                contact[step.side] = False
        if gap is None or step is None or not self.char_fsm.recovery_step or contact[step.side]:
            return contact
        if self.recovery.landing_due(state.time_s) and _sole_within_m(state, step.side, gap):
            contact[step.side] = True
        return contact

    def _rear_foot_bears_weight(self, sample: OperatorSample, analysis: OperatorAnalysis, op_state: Stance) -> bool:
        """Whether the operator's raised foot still carries weight: it is behind his stance foot, and his capture
        point is more than ``rear_foot_support_margin_m`` behind his stance sole's heel (the character's sole scaled
        to him), in the heading frame. Nobody stands on one foot with his capture point behind its heel: his rear
        foot, its heel raised above the stance threshold, still stands on its toes (a long, low stealthy stride).
        In a walk the rear foot lifts with the capture point ahead of the front ankle; walking backwards, with it
        behind the heel, his way going backwards in his own frame (``rear_foot_stepping_way_mps``): that foot steps.
        Not before the operator's COM velocity has settled (OPERATOR_VELOCITY_SETTLE_S): a recording that starts
        mid-stride starts with his filtered velocity at rest, his capture point on his COM, between his feet. Once
        read so (``_rear_foot_bearing``, the raised side, kept by :meth:`_track_stance`), the foot bears weight
        until his capture point is ``rear_foot_support_hysteresis_m`` less far behind the heel than the margin (a
        band, as the stance threshold's)."""
        margin = self.cfg.rear_foot_support_margin_m
        scale = self._last_scale()
        if margin is None or scale is None or sample.time_s < OPERATOR_VELOCITY_SETTLE_S:
            return False
        stance, raised = ("LEFT", "RIGHT") if op_state is Stance.LS else ("RIGHT", "LEFT")
        if self._rear_foot_bearing == swing_side(op_state):
            margin -= self.cfg.rear_foot_support_hysteresis_m
        forward = rot.matrix_from_quat(analysis.root_quat_wxyz)[:, 0]
        a = sample.pos[f"ANKLE_{stance}"]
        if float((sample.pos[f"ANKLE_{raised}"] - a)[:2] @ forward[:2]) >= 0.0:
            return False
        stepping_mps = self.cfg.rear_foot_stepping_way_mps
        if (stepping_mps is not None and self._way_heading.goes(stepping_mps)
                and self._way_heading.velocity_world[0] < 0.0):
            return False  # his way goes backwards in his own frame, towards the raised foot: it steps
        h_h = max(sample.com_world[2] - a[2], 0.1)
        xi_h = sample.com_world + self._com_h_rate.rate * np.sqrt(h_h / self.g)
        behind_heel_m = -(scale * float((xi_h - a)[:2] @ forward[:2]) - HEEL_AHEAD_OF_ANKLE_M)
        return behind_heel_m > margin

    def _track_stance(self, sample: OperatorSample, state: CharacterState,
                      analysis: OperatorAnalysis, mass: MassProperties) -> _Tick:
        """Both stance FSMs, the operator's swing time, and the sample the reference follows (held while the
        character waits for a late contact)."""
        swing_moving = False
        landing_mps = self.cfg.his_landing_max_speed_mps
        if landing_mps is not None:
            rates = {side: self._ankle_h_rate[side](sample.pos[f"ANKLE_{up}"]) for side, up in _SIDE_UP.items()}
            sw, scale = swing_side(self.op_fsm.state), self._last_scale()
            if sw is not None and scale is not None:
                swing_moving = scale * float(np.hypot(rates[sw][0], rates[sw][1])) > landing_mps
        op_state = self.op_fsm.update(sample.pos["ANKLE_LEFT"][2], sample.pos["ANKLE_RIGHT"][2], swing_moving)
        # His raised foot read as bearing weight (its side, for the band; none once his ankle heights say DS)
        bears = op_state is not Stance.DS and self._rear_foot_bears_weight(sample, analysis, op_state)
        self._rear_foot_bearing = swing_side(op_state) if bears else None
        if bears:
            op_state = Stance.DS
        contact = self._feet_down(state)
        # Only a lift-off from double stance can wait for the weight to shift.
        lifting = op_state is not Stance.DS and self.char_fsm.state is Stance.DS
        can_lift, behind = self._can_lift(sample, state, mass) if lifting else (None, set())
        lift_wait_s = self.cfg.liftoff_weight_shift_s
        if self.cfg.liftoff_behind_waits and swing_side(op_state) in behind:
            lift_wait_s = math.inf  # no weight shift brings back a capture point the body moves past
        ch_state = self.char_fsm.update(op_state, contact, state.time_s, can_lift, lift_wait_s)
        if self.char_fsm.recovery_step:
            self._feet_by_own_step = True
        elif ch_state is not Stance.DS:
            self._feet_by_own_step = False  # a swing of his
        if op_state is not Stance.DS:
            self._his_single_stance_s = state.time_s  # the last tick he stood on one foot [s]
        if op_state is not self._op_state:  # the operator's swing time, for the swing's progress
            if self._op_state is Stance.DS:
                self._op_last_ds_s = state.time_s - self._op_state_t0_s
                self._op_ds_s += 0.5 * (min(max(self._op_last_ds_s, 0.05), 1.0) - self._op_ds_s)
            if self._op_state in (Stance.LS, Stance.RS):
                self._his_landed_side = swing_side(self._op_state)
                swing_s = min(max(state.time_s - self._op_state_t0_s, 0.2), 1.0)
                self._op_swing_s += 0.5 * (swing_s - self._op_swing_s)
            self._op_state, self._op_state_t0_s = op_state, state.time_s
        if self.char_fsm.hold_reference and self._held is not None:
            s = self._held  # late contact: keep the reference until the character's foot lands
        else:
            s = sample
            self._held = sample
        return _Tick(sample=sample, s=s, analysis=analysis, op_state=op_state, ch_state=ch_state, contact=contact)

    # ---- 2. lower-body retargeting (Eq. 9-10) ----------------------------------------------------------------
    def _retarget_lower_body(self, tick: _Tick, state: CharacterState, mass: MassProperties) -> None:
        """The operator's size (Eq. 1, 9), then the pelvis and COM targets retargeted onto the character's feet."""
        s, analysis = tick.s, tick.analysis
        # Operator size: leg length by Eq. 1, smoothed; scale = h_C / h_H (Eq. 9).
        leg = analysis.leg_m if s is tick.sample else leg_length_m(s.pos, ankle_height_m=0.0)
        op_leg_m = leg if self._op_leg_m is None else self._op_leg_m + _SCALE_SMOOTHING * (leg - self._op_leg_m)
        self._op_leg_m = op_leg_m
        scale = CHAR_LEG_LENGTH_M / op_leg_m
        tick.op_leg_m, tick.scale = op_leg_m, scale

        tick.q_root_d = analysis.root_quat_wxyz
        R_root_d = tick.R_root_d = rot.matrix_from_quat(tick.q_root_d)
        a_h = tick.a_h = {k: s.pos[f"ANKLE_{v}"] for k, v in _SIDE_UP.items()}
        # The operator's feet the horizontal retargeting of Eq. 10 is anchored on: floor-filtered, as his COM
        # (operator_processing.py).
        a_hs = s.support_ankle_world
        a_c = tick.a_c = {k: state.link_origin_world[_LINK[f"{k}_ankle"]].copy() for k in _SIDE_UP}
        p_h = tick.p_h = operator_pelvis_world(s.pos, self.cfg.pelvis_from_hip_joints)
        com_h = tick.com_h = s.com_world
        com_c = tick.com_c = mass.com(state)
        tick.com_vel_c = mass.com_velocity(state)

        # Lower-body retargeting (Eq. 9-10) for the pelvis and the COM, anchored on the feet the operator stands
        # on (on the character's stance while a late contact holds the reference): after an early contact
        # (Sec. 5.1) the character is in double stance while the operator still swings a foot, whose position
        # says nothing of where his body is over the ground.
        anchor = tick.ch_state if self.char_fsm.hold_reference else tick.op_state
        ground_z = self._ground_ankle_height_m(a_h, op_leg_m)
        if anchor is Stance.DS:
            order = self.cfg.fraction_needs_feet_in_his_order and self._feet_by_own_step
            pelvis_xy = _heading_frame_fraction(p_h, a_hs["left"], a_hs["right"], a_c["left"], a_c["right"],
                                                scale, R_root_d, order)
            com_xy = _heading_frame_fraction(com_h, a_hs["left"], a_hs["right"], a_c["left"], a_c["right"],
                                             scale, R_root_d, order)
            ankle_h_z = (0.5 * (ground_z["left"] + ground_z["right"]) if self.cfg.ds_anchor_ground_height
                         else 0.5 * (a_h["left"][2] + a_h["right"][2]))
        else:
            st = "left" if anchor is Stance.LS else "right"
            pelvis_xy = a_c[st] + scale * (p_h - a_hs[st])
            com_xy = a_c[st] + scale * (com_h - a_hs[st])
            ankle_h_z = ground_z[st]
        tick.ankle_h_z = ankle_h_z
        # A change of stance changes the anchor of Eq. 10 (the fraction between the feet, or the stance foot); the
        # operator's and the character's feet are never placed exactly alike, so the targets would jump. The jump
        # is taken up as an offset that decays with ANCHOR_BLEND_S. It is measured from the last target, which
        # carries the offset already: the offset left at the change is counted twice, and at changes closer than the
        # decay (a run's) it grows, the targets ahead of a character that steps shorter than its operator. Measured,
        # the offset that keeps the target exactly continuous lost 12 of 352 runs, most of them runs
        # (docs/decisions.md, "The anchor offset at a run's stance changes").
        if anchor is not self._anchor_stance and self._last_xy is not None:
            self._anchor_offset += self._last_xy - np.array([pelvis_xy[:2], com_xy[:2]])
        self._anchor_stance = anchor
        self._anchor_offset *= self._anchor_decay
        pelvis_xy = np.array([*(pelvis_xy[:2] + self._anchor_offset[0]), 0.0])
        com_xy = np.array([*(com_xy[:2] + self._anchor_offset[1]), 0.0])
        if self.cfg.late_contact_keeps_momentum:
            # A held reference (late contact) holds the operator's pose, not his progress over the ground: the
            # targets go on at the desired COM velocity the hold began with, so that the character's momentum is
            # not braked towards where he was.
            if self.char_fsm.hold_reference:
                if self._hold_velocity is None:
                    self._hold_velocity = self._com_d_rate.rate[:2].copy()
                self._hold_shift = self._hold_shift + self._hold_velocity * self.dt_s
                pelvis_xy[:2] += self._hold_shift
                com_xy[:2] += self._hold_shift
            else:
                self._hold_velocity, self._hold_shift = None, np.zeros(2)
        self._last_xy = np.array([pelvis_xy[:2], com_xy[:2]])
        if self.cfg.rest_step_min_m is not None and (self._rest_stance is not None or self._rest_offset_xy.any()):
            shift = self._rest_shift_xy(tick, state, com_xy)
            pelvis_xy[:2] += shift
            com_xy[:2] += shift
        # Both targets moved towards his COM on the character's path (path_feedback.py; after the anchor offset's
        # continuity, which is the feet's, not the path's), while he steps along his way no faster than the
        # character's gait goes (the pull is not computed while none of it is kept)
        if self.cfg.path_target_share > 0.0:
            kept = self._path_pull_kept(state.time_s)
            along = self._path_pull_along(scale)
            if kept != 0.0 and along != 0.0:
                pull = self.path.target_pull_xy(com_xy, com_h, scale) * kept * along
                pelvis_xy[:2] += pull
                com_xy[:2] += pull
        tick.he_stands = self._he_stands(state, scale, tick.op_state)
        tick.his_feet_still = self._his_feet_still(a_hs, scale)  # (the rest steps; ReferencePose.both_stand_still)
        tau = self.cfg.reference_follows_operator_s
        if tau > 0:
            # The targets advance at the operator's COM velocity (scaled), pulled towards the anchored ones with time
            # constant tau, instead of taking up each anchor change as a decaying offset (which moves the targets back
            # at every stance change of a character whose steps are shorter than his, and brakes it); while he stands,
            # once they are on the anchored ones, with reference_follows_standing_s.
            raw = np.array([pelvis_xy[:2], com_xy[:2]])
            if (self.cfg.reference_follows_standing_s is not None and tick.he_stands
                    and self._ref_xy is not None and float(np.abs(self._ref_xy - raw).max()) < _STANDING_LEAD_M):
                tau = self.cfg.reference_follows_standing_s
            if self.char_fsm.hold_reference and self._hold_velocity is not None:
                v_ff = self._hold_velocity
            else:
                v_ff = scale * self._com_h_rate.rate[:2]
            if self._ref_xy is None:
                self._ref_xy = raw.copy()
            else:
                pred = self._ref_xy + v_ff * self.dt_s
                self._ref_xy = pred + min(self.dt_s / max(tau, 1e-9), 1.0) * (raw - pred)
                lead_max = self.cfg.reference_lead_max_m
                if lead_max is not None:  # no further from the anchored targets than this
                    lead = self._ref_xy - raw
                    norms = np.linalg.norm(lead, axis=1, keepdims=True)
                    self._ref_xy = raw + lead * np.minimum(1.0, lead_max / np.maximum(norms, 1e-12))
            pelvis_xy[:2], com_xy[:2] = self._ref_xy[0], self._ref_xy[1]
        # ... lowered by the offset as he goes somewhere (his smoothed COM rate, scaled; none by default)
        cfg = self.cfg
        offset_m = 0.0
        if cfg.pelvis_height_offset_m:
            his_speed_mps = scale * float(np.hypot(self._com_h_rate.rate[0], self._com_h_rate.rate[1]))
            offset_m = pelvis_offset_m(cfg.pelvis_height_offset_m, his_speed_mps, cfg.pelvis_offset_full_speed_mps,
                                       cfg.pelvis_offset_start_speed_mps)
        tick.pelvis_offset_m = offset_m
        tick.pelvis_d = np.array([pelvis_xy[0], pelvis_xy[1],  # Eq. 9
                                  ANKLE_HEIGHT_M + scale * (p_h[2] - ankle_h_z) + offset_m])
        tick.pelvis_vel_z = scale * float(self._pelvis_h_rate(p_h)[2])
        if self._his_rise is not None:
            tick.pelvis_vel_z = self._his_rise.rise_mps(tick.pelvis_vel_z, tick.op_state is Stance.DS)
        floor_m = self.cfg.pelvis_min_height_m
        if floor_m is not None and below_crouch_floor(tick.pelvis_d[2], floor_m, s.pos["NECK"] - p_h):
            # (lowered by the offset only as far as the floor: a crouch of his own below it is not the offset's)
            tick.pelvis_offset_m = min(0.0, floor_m - (float(tick.pelvis_d[2]) - offset_m))
            tick.pelvis_d[2] = floor_m  # his crouch followed down to the floor, above a fall's height
            tick.pelvis_vel_z = max(tick.pelvis_vel_z, 0.0)
        # The operator's COM height reflects his own mass distribution, not the character's: the vertical is left
        # to the pelvis height (Eq. 9) through the leg IK, and the COM target keeps the character's own height.
        tick.com_d = np.array([com_xy[0], com_xy[1], com_c[2]])
        # The desired COM velocity is the rate of change of this target (smoothed), not the operator's own COM
        # velocity scaled: the two differ whenever the feet the target is anchored on differ (a foot the operator
        # slides or places elsewhere), and a velocity target that disagrees with the position target drives the
        # COM past it.
        com_vel_d = self._com_d_rate(tick.com_d)
        com_vel_d[2] = 0.0
        tick.com_vel_h = self._com_h_rate(com_h)
        if self._tracks_way:
            self.way.update(scale * tick.com_vel_h)
        if self.cfg.rear_foot_stepping_way_mps is not None:
            # ... and in his heading frame: a walk backwards goes backwards in it for as long as it lasts, a spin's
            # way turns round in it and averages out
            self._way_heading.update(tick.R_root_d[:2, :2].T @ (scale * tick.com_vel_h[:2]))
        keep_m = self.cfg.double_stance_keeps_momentum_m
        if (keep_m is not None and anchor is Stance.DS and self._his_gait(tick, a_hs)
                and self._capture_near_support(tick, state, keep_m)):
            com_vel_d = kept_com_velocity(com_vel_d, scale * tick.com_vel_h, tick.com_vel_c)
        tick.com_vel_d = com_vel_d
        if self.path.enabled:
            xi_c, omega = capture_point(com_c, tick.com_vel_c, self.g)
            self.path.update(state.root_pos_world, p_h, xi_c, self._operator_capture_point(tick), scale, omega)

    def _path_pull_kept(self, time_s: float) -> float:
        """The share of the targets' pull onto his path kept at ``time_s`` [s]: at his way's speed over the ground
        (operator_way.py, scaled; as of the last tick), path_feedback.pull_share_at_speed, and as long ago as he last
        stood on one foot, path_feedback.pull_share_after_steps [-]."""
        return (pull_share_at_speed(float(np.hypot(*self.way.velocity_world)), self.cfg.path_target_fade_from_mps,
                                    self.cfg.path_target_fade_to_mps)
                * pull_share_after_steps(time_s - self._his_single_stance_s, self.cfg.path_target_step_hold_s))

    def _path_pull_along(self, scale: float) -> float:
        """The share of the targets' pull kept as he goes along his way [-]: how much of the last
        ``operator_way_time_s`` his (scaled) COM velocity went along his way over the ground, at least
        ``path_target_along_min_mps`` fast and within the angle whose cosine is ``path_target_along_cos``
        (operator_way.OperatorWay.goes_along, as of the last tick), averaged over that time. A walk goes along its
        way; a dance's sway, a spin's circle and a turn on the spot do not, and the character follows those by
        turning and stepping in place, where a pull towards his path moves the body only by steps of its own. 1
        without ``path_target_along_cos``."""
        if self.cfg.path_target_along_cos is None:
            return 1.0
        along = self.way.goes_along(self.cfg.path_target_along_min_mps, scale * self._com_h_rate.rate[:2],
                                    self.cfg.path_target_along_cos)
        self._pull_along += self._pull_along_share * ((1.0 if along else 0.0) - self._pull_along)
        return self._pull_along

    def _rest_shift_xy(self, tick: _Tick, state: CharacterState, com_xy: np.ndarray) -> np.ndarray:
        """(2,) what the targets move by for a step to where he stands [m]: onto the centre of the sole the weight is
        to be on (:meth:`_rest_step`), the target moving at most ``rest_step_shift_mps``; back again at that rate once
        no such step is under way."""
        limit = self.cfg.rest_step_shift_mps * self.dt_s
        if self._rest_stance is None:
            self._rest_com_xy = None
            self._rest_offset_xy = self._rest_offset_xy - bounded_xy(self._rest_offset_xy, limit)
            return self._rest_offset_xy
        ankle = tick.a_c[self._rest_stance]
        yaw = rot.twist_angle(state.link_quat_wxyz[_LINK[f"{self._rest_stance}_ankle"]], _UP)
        centre = ankle[:2] + FOOT_CENTER_AHEAD_OF_ANKLE_M * np.array([math.cos(yaw), math.sin(yaw)])
        if self._rest_com_xy is None:
            self._rest_com_xy = com_xy[:2] + self._rest_offset_xy
        self._rest_com_xy = self._rest_com_xy + bounded_xy(centre - self._rest_com_xy, limit)
        self._rest_offset_xy = self._rest_com_xy - com_xy[:2]
        return self._rest_offset_xy

    def _his_feet_still(self, his_feet_world: dict[str, np.ndarray], scale: float) -> bool:
        """Whether his feet (``his_feet_world``, the ankles Eq. 10 is anchored on) are at rest: their fastest speed over
        the ground, scaled, smoothed over _FEET_SPEED_SMOOTHING_S, below _FEET_STILL_MPS. His COM may be at rest while
        a foot slides or turns on the ground (a dance, the start of a spin): his feet are not where he stands then."""
        left, right = his_feet_world["left"], his_feet_world["right"]
        now = (float(left[0]), float(left[1]), float(right[0]), float(right[1]))
        last, self._his_feet_last = self._his_feet_last, now
        if last is not None:
            moved = max(math.hypot(now[0] - last[0], now[1] - last[1]), math.hypot(now[2] - last[2], now[3] - last[3]))
            share = min(self.dt_s / _FEET_SPEED_SMOOTHING_S, 1.0)
            self._his_feet_speed_mps += share * (moved * scale / self.dt_s - self._his_feet_speed_mps)
        return self._his_feet_speed_mps < _FEET_STILL_MPS

    def _he_stands(self, state: CharacterState, scale: float, op_state: Stance) -> bool:
        """Whether he has stood on both feet for _STANDING_FOR_S or longer (``op_state`` his stance): his COM's scaled
        speed below _STANDING_SPEED_MPS, now and averaged over his way (operator_way.py), and no foot lifted (a spin
        on the spot steps); standing from the start counts from before it."""
        if op_state is not Stance.DS or self.way.goes(_STANDING_SPEED_MPS, scale * self._com_h_rate.rate[:2]):
            self._stands_since_s = None
        elif self._stands_since_s is None:
            self._stands_since_s = state.time_s
        return self._stands_since_s is not None and state.time_s - self._stands_since_s >= _STANDING_FOR_S

    def _capture_near_support(self, tick: _Tick, state: CharacterState, within_m: float,
                              sides: list[str] | None = None) -> bool:
        """Whether the character's capture point is within ``within_m`` outside the support polygon of its soles on
        the ground, or of the soles ``sides`` if given (inside counts; no sole: False) [m]."""
        on_ground = soles_on_ground(state) if sides is None else sides
        if not on_ground:
            return False
        xi_c, _ = capture_point(tick.com_c, tick.com_vel_c, self.g)
        quats = {s: state.link_quat_wxyz[_LINK[f"{s}_ankle"]] for s in on_ground}
        return support_outside_m(xi_c, tick.a_c, quats, on_ground) <= within_m

    def _ground_ankle_height_m(self, ankle_h: dict[str, np.ndarray], op_leg_m: float) -> dict[str, float]:
        """Per side, the height of the operator's ankle the pelvis height of Eq. 9 is measured from [m]: the ankle's
        own while it can bear weight; the one it had when it left the ground while it is higher than
        ``MotionConfig.airborne_ankle_height_leg`` of his leg above his floor (he is in the air: his pelvis's height
        above that foot is not a stance leg's). His floor is the lowest his ankles have been, rising towards his
        lower ankle at most at OPERATOR_FLOOR_RISE_MPS (stairs up; a low glitch of the sensor is forgotten)."""
        share = self.cfg.airborne_ankle_height_leg
        floor = min(ankle_h["left"][2], ankle_h["right"][2])
        if self._op_ankle_floor_z is not None:
            floor = min(floor, self._op_ankle_floor_z + OPERATOR_FLOOR_RISE_MPS * self.dt_s)
        self._op_ankle_floor_z = floor
        for side in ("left", "right"):
            z = float(ankle_h[side][2])
            if share is None or z - floor <= share * op_leg_m or side not in self._op_ankle_ground_z:
                self._op_ankle_ground_z[side] = z
        return self._op_ankle_ground_z

    # ---- 3. foot targets: planted feet, swing-foot planning (Eq. 28) -----------------------------------------
    def _plan_feet(self, tick: _Tick, state: CharacterState, mass: MassProperties) -> None:
        """A planted foot where it is, the swing foot where the operator's is (or where a recovery step lands); the
        pelvis lowered as far as a foot that must land needs."""
        self._record_his_landing(tick)
        self._recovery_step(tick, state)
        self._land_overrun_swing(tick, state)
        tick.weights = stance_weights(tick.ch_state, self._ds_left_share(tick.com_c, tick.a_c))
        if tick.ch_state is Stance.DS and (self._rest_stance is not None or self._rest_offset_xy.any()):
            # A weight shift for a step to where he stands, or its release after the landing: the COM over one foot
            # leaves the other no share of the weight, and a foot with none is free to the controller's tasks (it
            # slides over the ground). Both keep at least a share.
            low = REST_FOOT_MIN_WEIGHT
            tick.weights = {side: min(max(w, low), 1.0 - low) for side, w in tick.weights.items()}
        sw = tick.swing = swing_side(tick.ch_state)
        for side in ("left", "right"):
            if side == sw and self.char_fsm.recovery_step:
                other = OTHER_SIDE[side]
                com_vel = (mass.com_velocity_carried(state, LEG_LINKS[side], _ROOT_LINK)
                           if self.cfg.recovery_landing_without_swing else tick.com_vel_c)
                tick.targets[side] = self.recovery.swing_target(
                    state.time_s, tick.com_c, com_vel, tick.a_c[other],
                    state.link_quat_wxyz[_LINK[f"{other}_ankle"]], tick.R_root_d, self._walk_on(tick),
                    state.link_origin_world[_LINK[f"{side}_ankle"]])
                tick.foot_yaw[side] = (float(np.arctan2(tick.R_root_d[1, 0], tick.R_root_d[0, 0]))
                                       if self.cfg.foot_yaw_control  # along the heading, as its landing is planned
                                       else rot.twist_angle(state.link_quat_wxyz[_LINK[f"{side}_ankle"]], _UP))
            elif side == sw:
                tick.targets[side] = self._swing_target(tick, state, side)
                tick.foot_yaw[side] = rot.twist_angle(tick.s.quat[f"ANKLE_{_SIDE_UP[side]}"], _UP)
            else:
                # Planted feet are flat on the (level) ground: their ankle height is the model's, not the measured
                # one, which rises when a foot rolls and would feed back into the pelvis height of Eq. 9.
                a = tick.a_c[side]
                tick.targets[side] = np.array([a[0], a[1], ANKLE_HEIGHT_M])
                yaw = rot.twist_angle(state.link_quat_wxyz[_LINK[f"{side}_ankle"]], _UP)
                if self.cfg.foot_yaw_control:
                    # Where it presses the ground its sole's friction holds it; unloaded, it keeps the yaw it had.
                    if tick.contact[side] or side not in self._planted_yaw:
                        self._planted_yaw[side] = yaw
                    yaw = self._planted_yaw[side]
                tick.foot_yaw[side] = yaw
            if side == sw:
                self._planted_yaw.pop(side, None)
        self._swing = sw
        # A foot that has to reach the ground and does not touch it yet (a stance foot, or the swing foot held
        # for a late contact; not one lying on it unpressed, landing_reach_ground_gap_m) must be within the leg's
        # reach of its hip: the pelvis is lowered as far as that needs (no faster than landing_pelvis_descent_mps).
        # With the pelvis at the operator's height (Eq. 9) the legs are nearly straight, and a foot ahead of the body
        # could otherwise never land. It is lowered no further than landing_pelvis_floor_share of the reach above the
        # foot: a foot out of reach from the hip even then (the operator's pelvis target may be far from the body)
        # would otherwise put the pelvis target on the ground.
        landing_step = (self.cfg.recovery_landing_reach and self.char_fsm.recovery_step
                        and self.recovery.landing_due(state.time_s))
        if self._stance_reach_m is not None:
            # Opt-in: no higher than the planted stance legs reach (MotionConfig.pelvis_stance_reach_share)
            for side, sign in (("left", 1.0), ("right", -1.0)):
                if tick.weights[side] > 0 and tick.contact[side]:
                    tick.pelvis_d[2] = min(tick.pelvis_d[2], self._pelvis_within_m(tick, side, sign,
                                                                                  self._stance_reach_m))
        unlowered_z = float(tick.pelvis_d[2])
        ground_gap = self.cfg.landing_reach_ground_gap_m  # a foot this near the ground lies on it, pressed or not
        for side, sign in (("left", 1.0), ("right", -1.0)):
            must_land = tick.weights[side] > 0 or (side == sw and (self.char_fsm.hold_reference or landing_step))
            if must_land and not tick.contact[side] and not (ground_gap is not None
                                                              and _sole_within_m(state, side, ground_gap)):
                # The character's own step: from where its hip is (the operator's pelvis target may be anywhere
                # behind a body that carries momentum he does not have).
                hip_xy = state.link_origin_world[_LINK[f"{side}_hip"]][:2] if side == sw and landing_step else None
                lowered = self._pelvis_within_m(tick, side, sign, _LANDING_REACH_M, hip_xy)
                if lowered < tick.pelvis_d[2]:
                    tick.pelvis_d[2] = lowered
                    tick.pelvis_vel_z = 0.0
        if (self.cfg.swing_landing_within_reach and sw is not None
                and not self.char_fsm.recovery_step and not self.char_fsm.hold_reference
                and tick.swing_landing_xy is not None):
            # His swing: the target comes down by the swing's progress towards where its landing is within reach
            # (MotionConfig.swing_landing_within_reach), so that a late contact does not lower it within a tick.
            landing = np.array([*tick.swing_landing_xy, ANKLE_HEIGHT_M - LATE_CONTACT_PRESS_M])
            reach_z = self._pelvis_within_m(tick, sw, 1.0 if sw == "left" else -1.0, _LANDING_REACH_M,
                                            ankle_target=landing)
            progress = smooth_step((state.time_s - self._swing_t0_s) / self._op_swing_s)
            tick.pelvis_d[2] = min(float(tick.pelvis_d[2]),
                                   unlowered_z - progress * max(unlowered_z - reach_z, 0.0))
        rate = self.cfg.landing_pelvis_descent_mps
        if rate is not None:  # the lowering no faster than rate from the last tick's target
            if self._last_pelvis_z is not None and tick.pelvis_d[2] < unlowered_z:
                floor_z = self._last_pelvis_z - rate * self.dt_s
                tick.pelvis_d[2] = min(unlowered_z, max(float(tick.pelvis_d[2]), floor_z))
            self._last_pelvis_z = float(tick.pelvis_d[2])

    def _pelvis_within_m(self, tick: _Tick, side: str, sign: float, reach_m: float,
                         hip_xy: np.ndarray | None = None, ankle_target: np.ndarray | None = None) -> float:
        """The highest pelvis target [m] from which the leg on ``side`` (``sign`` +1 left, -1 right) reaches its
        ankle target (``ankle_target``, default this tick's) at ``reach_m`` hip to ankle, from ``hip_xy`` (default:
        the pelvis target's hip), no lower than landing_pelvis_floor_share of the landing reach above the target."""
        if hip_xy is None:
            hip_xy = (tick.pelvis_d + tick.R_root_d @ np.array([0.0, sign * HIP_HALF_WIDTH_M, 0.0]))[:2]
        target = tick.targets[side] if ankle_target is None else ankle_target
        d2 = float(np.sum((target[:2] - hip_xy) ** 2))
        above_foot = max(float(np.sqrt(max(reach_m * reach_m - d2, 0.0))), self._landing_pelvis_floor_m)
        return float(target[2]) + above_foot

    def _his_gait(self, tick: _Tick, his_ankles_world: dict[str, np.ndarray]) -> bool:
        """Whether the operator's double stance on ``his_ankles_world`` is a gait's: his COM moves from one foot
        towards the other (double_stance_momentum.moves_between_feet) and he goes somewhere, over the last second and
        now (operator_way.py, MotionConfig.gait_min_way_speed_mps), not a sway on the spot nor a stop."""
        return (moves_between_feet(tick.com_vel_h, his_ankles_world["left"], his_ankles_world["right"])
                and self.way.goes(self.cfg.gait_min_way_speed_mps, tick.scale * tick.com_vel_h))

    def _walk_on(self, tick: _Tick) -> WalkOn | None:
        """How the character's own step lands while the operator walks (recovery_step.WalkOn): None while he stands
        or does not go anywhere (MotionConfig.gait_min_way_speed_mps; the step stops the body), or with
        MotionConfig.recovery_walk_on_m None; along his way over the ground (operator_way.py, or his heading while
        the average is zero) with recovery_walk_on_his_way."""
        distance_m = self.cfg.recovery_walk_on_m
        now = tick.scale * tick.com_vel_h if self.cfg.recovery_walk_on_needs_motion_now else None
        if (distance_m is None or self._operator_stands(tick)
                or not self.way.goes(self.cfg.gait_min_way_speed_mps, now)):
            return None
        if not self.cfg.recovery_walk_on_his_way:
            return WalkOn(distance_m)
        way = self.way.direction_world()
        if way is None:
            way = _heading_world(tick)
        if self.cfg.recovery_walk_on_forward:
            forward = float(way @ _heading_world(tick))
            if forward <= 0.0:
                return None
            distance_m *= forward
        return WalkOn(distance_m, way)

    def _record_his_landing(self, tick: _Tick) -> None:
        """On the tick the operator lands a foot: its offset from his capture point, scaled, in his heading frame
        (the landing the character's swing on that side aims for relative to its own, swing_landing)."""
        side, self._his_landed_side = self._his_landed_side, None
        if side is not None and self._aim_at_his_landing:
            ankle = tick.sample.pos[f"ANKLE_{_SIDE_UP[side]}"]
            self._his_landing[side] = tick.R_root_d.T @ (tick.scale * (ankle - self._operator_capture_point(tick)))

    def _operator_capture_point(self, tick: _Tick) -> np.ndarray:
        """(3,) the operator's capture point, his COM height taken above his ankles plus the character's ankle
        height scaled to him [m]."""
        if tick.xi_h is None:
            h_h = max(tick.com_h[2] - tick.ankle_h_z + ANKLE_HEIGHT_M / tick.scale, 0.1)
            tick.xi_h = tick.com_h + tick.com_vel_h * np.sqrt(h_h / self.g)
        return tick.xi_h

    def _operator_stands(self, tick: _Tick, sides: tuple[str, ...] = ("left", "right")) -> bool:
        """Whether the operator's capture point is within the soles of his feet ``sides``
        (recovery_step.operator_stands); once a tick per set of feet."""
        if sides not in tick.stands:
            yaw_h = {s: rot.twist_angle(tick.s.quat[f"ANKLE_{_SIDE_UP[s]}"], _UP) for s in sides}
            tick.stands[sides] = operator_stands(self._operator_capture_point(tick), {s: tick.a_h[s] for s in sides},
                                                 yaw_h, tick.scale)
        return tick.stands[sides]

    def _capture_bounded(self, tick: _Tick) -> bool:
        """Whether the COM target's capture point is bounded to the character's soles this tick (capture_bound.py):
        in the character's double stance (but, with the opt-outs, not in his gait's double stance, nor while he is on
        one foot of his gait and the character on both), and in its single stance while the operator's capture point
        is within the soles he stands on (he balances on one leg, as in a kick, or he has stopped while the
        character's foot is still in the air)."""
        if tick.ch_state is Stance.DS:
            if tick.op_state is Stance.DS:
                # Opt-out: not while he walks from one foot onto the other (his gait's capture point runs ahead of
                # his front foot, and the character's, bounded within its soles, was braked at every double stance).
                return self.cfg.capture_bound_in_his_gait or not self._his_gait(tick, tick.sample.support_ankle_world)
            # He is on one foot, the character on both (its step landed before his): bounded; with the opt-out, still
            # while he does not walk his way, and while he does as in his single stance below.
            if self.cfg.capture_bound_before_his_landing or not self.way.goes_along(
                    self.cfg.gait_min_way_speed_mps, tick.scale * tick.com_vel_h, _GAIT_AXIS_COS):
                return True
        sides = tuple(s for s in _SIDE_UP if tick.op_state is Stance.DS or swing_side(tick.op_state) != s)
        return self._operator_stands(tick, sides)

    def _bounded_com_target(self, tick: _Tick, state: CharacterState, com_d: np.ndarray,
                            com_vel_d: np.ndarray, catch_step_s: float | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
        """The COM target with its capture point within the soles the character stands on, or, with
        ``catch_step_s``, at most as far outside them as a step that lands that long from now catches
        (capture_bound.py)."""
        soles = [sole_points_xy(tick.a_c[s], state.link_quat_wxyz[_LINK[f"{s}_ankle"]], self._sole_bound)
                 for s in soles_on_ground(state) if tick.weights[s] > 0.0]
        _, omega = capture_point(tick.com_c, tick.com_vel_c, self.g)
        margin_m = 0.0 if catch_step_s is None else gait_capture_margin_m(self.recovery.max_step_m, omega, catch_step_s)
        return bounded_com_target(com_d, com_vel_d, omega, soles, margin_m)

    def _landing_bounded_com_target(self, tick: _Tick, state: CharacterState, com_d: np.ndarray,
                                    com_vel_d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """In single stance, the COM target with its capture point where the planned landing catches it when the
        swing foot lands (the divergent component of motion, ξ̇ = ω (ξ - p)): within the stance sole, or within
        capture_bound.landing_catch_region, T the swing's remaining time at the operator's usual swing time. A
        capture point further out diverges beyond the landing before the foot is down: a long single stance (a slow,
        styled step) keeps it over the stance foot. With "sideways", only the change across the heading is taken."""
        assert tick.swing is not None and tick.swing_landing_xy is not None
        other = OTHER_SIDE[tick.swing]
        stance = sole_points_xy(tick.a_c[other], state.link_quat_wxyz[_LINK[f"{other}_ankle"]], self._sole_bound)
        _, omega = capture_point(tick.com_c, tick.com_vel_c, self.g)
        remaining_s = max(self._op_swing_s - (state.time_s - self._swing_t0_s), 0.0)
        offset = (float(tick.swing_landing_xy[0] - tick.a_c[other][0]),
                  float(tick.swing_landing_xy[1] - tick.a_c[other][1]))
        landing = landing_catch_region(stance, offset, math.exp(-omega * remaining_s))
        bounded, bounded_vel = bounded_com_target(com_d, com_vel_d, omega, [stance, landing])
        if self.cfg.landing_capture_bound == "sideways":  # only the change across the heading is taken
            side_axis = np.array([tick.R_root_d[0, 1], tick.R_root_d[1, 1], 0.0])
            side_axis /= max(float(np.linalg.norm(side_axis)), 1e-9)
            bounded = com_d + float(side_axis @ (bounded - com_d)) * side_axis
            bounded_vel = com_vel_d + float(side_axis @ (bounded_vel - com_vel_d)) * side_axis
        return bounded, bounded_vel

    def _stopping_landing(self, tick: _Tick, state: CharacterState, side: str, xi_h: np.ndarray,
                          landing: np.ndarray) -> np.ndarray:
        """The swing foot's landing when the operator stops on this step (his capture point within his soles,
        the swinging one where it is): if the character's capture point, when the foot lands, would be outside its
        stance sole and the planned landing, the landing of a recovery step (recovery_step.py) instead, so that
        the character can stop where he does."""
        if not self._operator_stands(tick):
            return landing
        stance_q = state.link_quat_wxyz[_LINK[f"{OTHER_SIDE[side]}_ankle"]]
        remaining_s = max(self._op_swing_s - (state.time_s - self._swing_t0_s), 0.0)
        capture, holds = self._landing_holds(tick, side, stance_q, landing, remaining_s)
        if holds:
            return landing
        self._stopping_capture_side = side  # landed by a recovery step next tick (_land_overrun_swing)
        return capture

    def _landing_holds(self, tick: _Tick, side: str, stance_quat_wxyz: np.ndarray, landing: np.ndarray,
                       in_s: float) -> tuple[np.ndarray, bool]:
        """The landing of a recovery step of ``side`` made ``in_s`` [s] from now (RecoveryStepper.capture_landing),
        and whether the capture point it predicts for then stands on the stance sole and a sole at ``landing`` (3,)
        [m] instead (recovery_step.stands_on)."""
        other = OTHER_SIDE[side]
        capture, xi_land = self.recovery.capture_landing(in_s, tick.com_c, tick.com_vel_c, tick.a_c[other],
                                                         stance_quat_wxyz, tick.R_root_d, side)
        return capture, stands_on(xi_land, tick.a_c[other], stance_quat_wxyz, landing, tick.R_root_d)

    def _recovery_step(self, tick: _Tick, state: CharacterState) -> None:
        """Ends a recovery step the stance FSM has ended; begins one when the character stands on both feet and its
        capture point has left its support polygon (recovery_step.py), and either the operator stands too or the
        character's double stance is overdue (:meth:`_double_stance_overdue`)."""
        stepper = self.recovery
        if stepper.step is not None and not self.char_fsm.recovery_step:
            stepper.end(state.time_s)
        self._rest_stance = None  # decided again below (_rest_step)
        if stepper.step is not None and stepper.step.fixed_landing:
            self._rest_stance = OTHER_SIDE[stepper.step.side]  # the weight stays on the other foot while it steps
        # The operator stands on both feet, or on one while the character, its step for his counted as taken,
        # stands on both and waits for his next change (the held last frame of a clip cut mid-swing): either way
        # the character does not follow a step of his now.
        waits = tick.op_state is Stance.DS or (self.cfg.recovery_while_step_counted and self.char_fsm.step_counted)
        if not waits:
            self._operator_stands_since_s = None
        if stepper.step is not None or tick.ch_state is not Stance.DS or self.char_fsm.hold_reference:
            self._outside_since_s = None
            return
        if self._double_stance_overdue(tick, state) and self._begin_recovery_step(tick, state):
            return
        if not waits:
            return
        if not self._operator_stands(tick):
            self._operator_stands_since_s = None  # he moves over his feet (a walk's double stance)
            return
        if self._operator_stands_since_s is None:
            self._operator_stands_since_s = state.time_s
        if state.time_s - self._operator_stands_since_s < self.cfg.recovery_min_stance_s:
            return  # a double stance shorter than this is a walk's: his next step is the character's
        if not self._begin_recovery_step(tick, state) and self.cfg.rest_step_min_m is not None:
            self._rest_step(tick, state)

    def _rest_step(self, tick: _Tick, state: CharacterState) -> None:
        """A step to where he stands (rest_step.py), while he has stood still for ``rest_step_after_s`` (as
        :meth:`_he_stands` reads it) and his feet are still (``his_feet_still``), and the character stands on both
        feet with its capture point within their support: the
        weight moved over the foot that stays (:meth:`_rest_shift_xy`, from the next tick on) while the step is
        planned, and the step begun once the capture point is WEIGHT_OVER_SOLE_M inside that sole."""
        cfg = self.cfg
        assert cfg.rest_step_min_m is not None
        on_ground = soles_on_ground(state)
        since_s = self._stands_since_s  # (_he_stands)
        stood = since_s is not None and state.time_s - since_s >= cfg.rest_step_after_s
        if len(on_ground) < 2 or not (stood and tick.his_feet_still):
            return
        quats = {s: state.link_quat_wxyz[_LINK[f"{s}_ankle"]] for s in _SIDE_UP}
        xi, _ = capture_point(tick.com_c, tick.com_vel_c, self.g)
        if support_outside_m(xi, tick.a_c, quats, on_ground) > 0.0:
            return
        goals = {}
        for side in _SIDE_UP:  # his feet on the character's path
            goal = self.path.on_path_xy(tick.s.support_ankle_world[side], tick.scale)
            if goal is None:
                return
            goals[side] = goal
        plan = rest_step_plan(goals, tick.a_c, tick.R_root_d, cfg.rest_step_min_m, cfg.rest_step_reach_m)
        if plan is None:
            return
        side, landing = plan
        last = self._rest_last
        if (last is not None and last[0] == side and np.hypot(*(last[1] - tick.a_c[side][:2])) < cfg.rest_step_min_m / 2
                and np.hypot(*(last[2] - landing[:2])) < cfg.rest_step_min_m / 2):
            return  # the same step from the same place again: the last did not hold (its foot slid back unloaded)
        stance = OTHER_SIDE[side]
        self._rest_stance = stance
        if sole_outside_m(xi, tick.a_c[stance], quats[stance]) > -WEIGHT_OVER_SOLE_M:
            return  # the weight is not over the foot that stays yet
        self.recovery.begin_to(side, state.time_s, tick.a_c[side], landing, cfg.rest_step_swing_s)
        self._rest_last = (side, tick.a_c[side][:2].copy(), landing[:2].copy())
        tick.ch_state = self.char_fsm.begin_recovery_step(side, state.time_s,
                                                          cfg.rest_step_swing_s + cfg.late_contact_timeout_s)
        self._swing_t0_s = state.time_s
        self.rest_steps += 1

    def _begin_recovery_step(self, tick: _Tick, state: CharacterState) -> bool:
        """A recovery step from double stance, if the capture point is outside the support by more than the margin
        (recovery_step.RecoveryStepper.trigger): whether one began."""
        quats = {s: state.link_quat_wxyz[_LINK[f"{s}_ankle"]] for s in _SIDE_UP}
        loads = ({s: state.foot_contact_force_n[f"{s}_ankle"] for s in _SIDE_UP}
                 if self.cfg.recovery_stance_min_load_share is not None else None)  # read only where they are used
        step = self.recovery.trigger(state.time_s, tick.com_c, tick.com_vel_c, tick.a_c, quats,
                                     soles_on_ground(state), tick.R_root_d, loads)
        if step is None:
            return False
        self._outside_since_s = None
        timeout_s = self.cfg.recovery_swing_s + self.cfg.late_contact_timeout_s
        tick.ch_state = self.char_fsm.begin_recovery_step(step.side, state.time_s, timeout_s)
        self._swing_t0_s = state.time_s
        return True

    def _double_stance_overdue(self, tick: _Tick, state: CharacterState) -> bool:
        """Step timing adapted to the balance in double stance: whether the character's capture point has been
        outside the support polygon of its soles on the ground, by more than the recovery step's margin, for
        ``recovery_double_stance_overrun`` times the operator's usual double stance, or at all behind the feet
        (``recovery_step_behind_cos``), or so far out that his next lift-off comes too late for any step
        (``recovery_ds_on_reach_limit``, :meth:`_his_lift_off_too_late`). A character's double stance ends with his
        next lift-off; where he walks on from a step the character has already landed, or holds a foot up at a clip's
        end, that lift-off comes after the capture point has run out of reach; and his next step forwards never
        reaches one behind the feet."""
        cfg = self.cfg
        on_ground = soles_on_ground(state)
        if cfg.recovery_double_stance_overrun <= 0.0 or not cfg.recovery_steps or not on_ground:
            self._outside_since_s = None
            return False
        xi, _ = capture_point(tick.com_c, tick.com_vel_c, self.g)
        quats = {s: state.link_quat_wxyz[_LINK[f"{s}_ankle"]] for s in on_ground}
        outside, along = support_outside_along(xi, tick.a_c, quats, on_ground, tick.R_root_d[:2, 0])
        if outside <= cfg.recovery_step_margin_m:
            self._outside_since_s = None
            return False
        if cfg.recovery_step_behind_cos is not None and along < -cfg.recovery_step_behind_cos:
            return True  # behind both feet: no step of his forwards catches it (his steps back, it steps first)
        if self._outside_since_s is None:
            self._outside_since_s = state.time_s
        if state.time_s - self._outside_since_s >= cfg.recovery_double_stance_overrun * self._op_ds_s:
            return True
        return cfg.recovery_ds_on_reach_limit and self._his_lift_off_too_late(tick, state, on_ground, quats)

    def _his_lift_off_too_late(self, tick: _Tick, state: CharacterState, on_ground: list[str],
                               quats: dict[str, np.ndarray]) -> bool:
        """Whether a step begun at the operator's next lift-off (:meth:`_wait_for_his_lift_off_s`) would land with
        the capture point out of a recovery step's reach whichever foot stands (recovery_step.out_of_reach_after_wait):
        waiting cannot be better then. Without ``recovery_ds_beyond_reach``, and with both soles on the ground, only
        where a recovery step begun now captures it (RecoveryStepper.capture_residual_m); with it, also where none
        does: the step that lands furthest towards it leaves the least for the next."""
        if not out_of_reach_after_wait(tick.com_c, tick.com_vel_c, self.g, tick.a_c, quats, on_ground,
                                       self._wait_for_his_lift_off_s(tick, state), self.cfg.recovery_swing_s,
                                       self.recovery.max_step_m):
            return False
        if len(on_ground) < 2 or self.cfg.recovery_ds_beyond_reach:
            return True
        return min(self.recovery.capture_residual_m(tick.com_c, tick.com_vel_c, tick.a_c[s], quats[s], tick.R_root_d,
                                                    OTHER_SIDE[s]) for s in on_ground) <= 0.0

    def _wait_for_his_lift_off_s(self, tick: _Tick, state: CharacterState) -> float:
        """How long until the operator's next lift-off, on his usual timing [s]: the rest of his double stance, or
        the rest of his swing and a double stance of his usual length."""
        elapsed_s = state.time_s - self._op_state_t0_s
        if tick.op_state is Stance.DS:
            return max(self._op_ds_s - elapsed_s, 0.0)
        return max(self._op_swing_s - elapsed_s, 0.0) + self._op_ds_s

    def _land_overrun_swing(self, tick: _Tick, state: CharacterState) -> None:
        """Step timing adapted to the balance: a swing that has lasted ``recovery_swing_overrun`` times the
        operator's usual swing time (he holds a foot up: a pose on one leg, the held last frame of a clip) while the
        character's capture point has left its stance sole by more than the margin (it cannot stand on one foot
        as he does) becomes a recovery step, which lands the foot where the capture point will be. With
        ``recovery_on_stopping_step``, a swing whose landing the last tick's :meth:`_stopping_landing` moved to catch
        the capture point (he stops on this step, the character cannot) becomes one at once: his foot, lowered as
        he comes to rest, would land it 0.3-0.5 s later while the capture point runs on. With
        ``recovery_on_reach_limit``, so does a swing that, held to his timing, would land when the capture point is
        already out of a recovery step's reach (:meth:`_capture_beyond_reach_at_his_landing`). With
        ``recovery_in_late_contact`` these rules also take over a swing held for a late contact, unless his landing,
        as the swing last planned it, would hold the capture point a recovery swing from now."""
        cfg = self.cfg
        sw = swing_side(tick.ch_state)
        overrun_s = cfg.recovery_swing_overrun * self._op_swing_s
        stopping_side, self._stopping_capture_side = self._stopping_capture_side, None
        if cfg.recovery_on_stopping_step and stopping_side is not None and stopping_side == sw:
            overrun_s = 0.0
        if (not cfg.recovery_steps or sw is None or sw != self._swing or self.char_fsm.recovery_step
                or (self.char_fsm.hold_reference and not cfg.recovery_in_late_contact)):
            return
        other = OTHER_SIDE[sw]
        stance_q = state.link_quat_wxyz[_LINK[f"{other}_ankle"]]
        if self.char_fsm.hold_reference and self._planned_landing_xy is not None:
            # A held swing (recovery_in_late_contact) lands where he did: taken over only if that landing would not
            # hold the capture point a recovery swing from now.
            landing = np.array([*self._planned_landing_xy, ANKLE_HEIGHT_M])
            if self._landing_holds(tick, sw, stance_q, landing, cfg.recovery_swing_s)[1]:
                return
        if (overrun_s > 0.0 and cfg.recovery_on_reach_limit
                and self._capture_beyond_reach_at_his_landing(tick, state, sw, stance_q)):
            overrun_s = 0.0
        if state.time_s - self._swing_t0_s < overrun_s:
            return
        xi, _ = capture_point(tick.com_c, tick.com_vel_c, self.g)
        if sole_outside_m(xi, tick.a_c[other], stance_q) <= cfg.recovery_step_margin_m:
            return
        self.recovery.take_over(sw, state.time_s, state.link_origin_world[_LINK[f"{sw}_ankle"]])
        self.char_fsm.take_over_swing(state.time_s, cfg.recovery_swing_s + cfg.late_contact_timeout_s)

    def _capture_beyond_reach_at_his_landing(self, tick: _Tick, state: CharacterState, side: str,
                                            stance_quat_wxyz: np.ndarray) -> bool:
        """Whether the capture point, at the end of the operator's usual swing time from the swing's start, will be
        further from the stance ankle than a recovery step reaches: the balance has to land the swing of ``side``
        before he would (recovery_step.capture_point_after, as a recovery step's landing predicts it). Past his
        usual swing time the landing is predicted a recovery swing from now with ``recovery_overdue_swing_horizon``
        (the soonest any landing can come), and now without."""
        ankle = tick.a_c[OTHER_SIDE[side]]
        elapsed_s = state.time_s - self._swing_t0_s
        remaining_s = max(self._op_swing_s - elapsed_s, 0.0)
        if self.cfg.recovery_overdue_swing_horizon and elapsed_s >= self._op_swing_s:
            remaining_s = self.cfg.recovery_swing_s
        x, y = capture_point_after(tick.com_c, tick.com_vel_c, self.g, ankle, stance_quat_wxyz, remaining_s)
        return math.hypot(x - float(ankle[0]), y - float(ankle[1])) > self.recovery.max_step_m

    def _swing_target(self, tick: _Tick, state: CharacterState, side: str) -> np.ndarray:
        """Where the swing foot goes this tick.

        Where the operator's foot is, scaled, relative to the character's body ("pelvis": from its pelvis as his
        is from his; no balance feedback, as Sec. 7.2's c_d = c_v = 0), or ("capture_point") on the way from
        where the character's foot lifted off to where it lands relative to the character's capture point
        (COM + v / ω, ω = sqrt(g / h), the LIPM of Eq. 21) as his landed relative to his the last time on that side
        (``swing_landing``), within the landing limits: a character slower or faster than the operator steps
        shorter or further, as far as it needs to stop over its feet (a foot-position form of Eq. 12's feedback).
        The way is covered with the swing's progress (its time over the operator's usual swing time); the foot's
        height is his, scaled (his style). With ``swing_within_reach`` the target is kept within the leg's
        horizontal reach of its hip, the pelvis at its landing floor.
        """
        cfg = self.cfg
        other = OTHER_SIDE[side]
        a_h, a_c, scale, R_root_d = tick.a_h, tick.a_c, tick.scale, tick.R_root_d
        first_tick = self._swing != side
        if first_tick and self._aim_at_his_landing:
            # The swing's progress and start are this swing's from its first tick. (With "his_foot_now" the first
            # tick's progress is the last swing's, as that swing was built and measured: its target is then the
            # full landing, and the start's blend below takes a stride back from there.)
            self._swing_t0_s = state.time_s
            self._liftoff_xy = a_c[side][:2].copy()
        target = tick.pelvis_d + scale * (a_h[side] - tick.p_h)
        # His foot's height above his ground is his style (Sec. 5.2): a pelvis target lowered from his
        # (pelvis_height_offset_m) does not lower the swing foot with it.
        target[2] -= tick.pelvis_offset_m
        if cfg.swing_placement == "capture_point":
            com_c = tick.com_c
            xi_c = com_c + tick.com_vel_c * np.sqrt(max(com_c[2], 0.1) / self.g)
            xi_h = self._operator_capture_point(tick)
            last = self._his_landing.get(side)
            if self._aim_at_his_landing and (last is not None or self._his_landing):
                # his last landing on this side; if he has landed only the other foot yet, that one mirrored
                land = last.copy() if last is not None else self._his_landing[other] * _MIRROR_Y
            else:  # his swing foot's present offset (heading frame, from the capture point)
                land = R_root_d.T @ (scale * (a_h[side] - xi_h))
            start = (self._liftoff_xy if self._aim_at_his_landing
                     else (a_c[other] + scale * (a_h[side] - a_h[other]))[:2])
            path_shift = np.zeros(2)
            if self.cfg.path_feedback_share > 0.0:
                path_shift = R_root_d.T[:2, :2] @ self.path.landing_shift_xy(self._op_swing_s + self._op_ds_s)
            land[0] += path_shift[0]  # following him over the ground (path_feedback.py), within the bounds below
            land[0] = min(land[0], -cfg.step_behind_capture_point_m)
            if self._aim_at_his_landing and cfg.step_behind_capture_point_max_m is not None:
                land[0] = max(land[0], -cfg.step_behind_capture_point_max_m)
            out = 1.0 if side == "left" else -1.0
            land[1] = out * min(max(out * land[1], cfg.step_outside_capture_point_m[0]),
                                cfg.step_outside_capture_point_m[1])
            land[1] += path_shift[1]
            progress = smooth_step((state.time_s - self._swing_t0_s) / self._op_swing_s)
            landing = xi_c + R_root_d @ land
            if cfg.recovery_steps:
                landing = self._stopping_landing(tick, state, side, xi_h, landing)
            tick.swing_landing_xy = landing[:2]
            self._planned_landing_xy = tick.swing_landing_xy  # (a fresh array each tick, not changed after)
            target[:2] = start + progress * (landing[:2] - start)
            if cfg.free_swing:  # a swing neither needs to land: his foot from the stance foot (a kick's strike)
                if first_tick:
                    self._free_share = 0.0
                share = self._free_swing_share(tick, state, side)
                his = a_c[other][:2] + scale * (a_h[side] - a_h[other])[:2]
                target[:2] += share * (his - target[:2])
        else:
            target[:2] = (state.root_pos_world + scale * (a_h[side] - tick.p_h))[:2]
        target[2] = min(max(target[2], ANKLE_HEIGHT_M), ANKLE_HEIGHT_M + cfg.max_swing_foot_lift_m)
        if self.char_fsm.hold_reference:
            # Late contact (Sec. 5.1): the operator has landed, the character's foot has not. The held reference
            # keeps the foot where the operator put it, horizontally, and lowers it to the ground (slightly below,
            # so that it does touch).
            target[2] = ANKLE_HEIGHT_M - LATE_CONTACT_PRESS_M
        bound = step_length_bound_m(CHAR_LEG_LENGTH_M, tick.op_leg_m)  # Eq. 28
        step = target[:2] - a_c[other][:2]
        dist = float(np.linalg.norm(step))
        tick.step_exceeded = dist > bound
        self.bounds.report("step_length", tick.step_exceeded, state.time_s, "step %.2f m > bound %.2f m (Eq. 28)",
                           dist, bound)
        if tick.step_exceeded:
            target[:2] = a_c[other][:2] + step * (bound / dist)
        # The swing starts where the foot lifts off: the difference to the first target is taken up over
        # SWING_BLEND_S (a target jump would swing the leg hard enough to lift the stance foot).
        if first_tick:
            self._swing_offset = a_c[side][:2] - target[:2]
            self._swing_t0_s = state.time_s
        self._swing_offset *= self._swing_decay
        target[:2] += self._swing_offset
        if cfg.swing_within_reach:
            # Where the leg can land it: a target beyond that is followed by a foot that hovers while the body falls.
            hip = state.link_origin_world[_LINK[f"{side}_hip"]]
            away = target[:2] - hip[:2]
            dist = float(np.linalg.norm(away))
            if dist > self._swing_reach_m:
                target[:2] = hip[:2] + away * (self._swing_reach_m / dist)
        return target

    def _free_swing_share(self, tick: _Tick, state: CharacterState, side: str) -> float:
        """How much [0, 1] the character's swing foot follows his foot relative to the stance foot (scaled) rather
        than its way to the landing (MotionConfig.free_swing): 1 while his capture point is within the sole he
        stands on and the character's within its own (neither needs the swing foot to land: a kick, a raised leg),
        0 otherwise; it moves between the two over FREE_SWING_BLEND_S, so that the target does not jump."""
        other = OTHER_SIDE[side]
        free = self._operator_stands(tick, (other,)) and self._capture_near_support(tick, state, 0.0, [other])
        step = self.dt_s / FREE_SWING_BLEND_S
        self._free_share = min(self._free_share + step, 1.0) if free else max(self._free_share - step, 0.0)
        return self._free_share

    # ---- 4. leg IK (Sec. 5.3) and balance strategy (Sec. 5.4) ------------------------------------------------
    def _solve_legs(self, tick: _Tick, state: CharacterState) -> tuple[dict[str, np.ndarray], dict[str, float]]:
        """Each leg's hip, knee and ankle: IK in the motion plane N, Eq. 11 on a stance hip, Eq. 12 on the swing
        hip, feet flat. Returns local rotations (canonical) and hinge angles [rad]."""
        cfg = self.cfg
        local: dict[str, np.ndarray] = {}
        knee_angle: dict[str, float] = {}
        q_cur = state.joint_pos
        sw, q_root_d, features = tick.swing, tick.q_root_d, tick.analysis.features
        for side, sign in (("left", 1.0), ("right", -1.0)):
            hip_w = tick.pelvis_d + tick.R_root_d @ np.array([0.0, sign * HIP_HALF_WIDTH_M, 0.0])
            q_root_frame = q_root_d
            if side == sw:
                # The swing leg is solved from where its hip actually is (as SIMBICON's world-frame swing hip):
                # solved from the desired pelvis, a pelvis a little low or tilted would drive the foot into the
                # ground and lift the body off its stance foot.
                hip_w = state.link_origin_world[_LINK[f"{side}_hip"]].copy()
                q_root_frame = state.root_quat_wxyz
            N = features.N_l if side == "left" else features.N_r
            other = OTHER_SIDE[side]
            ik = solve_leg(hip_w, tick.targets[side], THIGH_LENGTH_M, SHANK_LENGTH_M, N)
            q_thigh = ik.thigh_quat_wxyz
            if side == sw:
                q_thigh = swing_hip_feedback(q_thigh, np.zeros(3), tick.com_c - tick.a_c[other], np.zeros(3),
                                             tick.com_vel_c, cfg.swing_hip_cd, cfg.swing_hip_cv, features.H)
            q_hip = rot.multiply(rot.conjugate(q_root_frame), q_thigh)
            if tick.weights[side] > 0 and tick.ch_state is not Stance.DS:
                q_hip_cur = canonical_quat_from_model(q_cur[JOINT_NAMES.index(f"{side}_hip")])
                q_hip = stance_hip_blend(q_hip, q_hip_cur, cfg.stance_hip_weight_w0)  # Eq. 11
            local[f"{side}_hip"] = q_hip
            knee_angle[f"{side}_knee"] = ik.knee_angle_rad
            q_foot = rot.quat_from_yaw(tick.foot_yaw[side])
            # Feet flat (Sec. 5.3). A planted foot on the IK's shank, which keeps the ankles' stiffness against
            # leaning; the swing foot on the actual shank, so that it is flat in the world whatever the swing leg's
            # tracking error, and lands on its sole rather than an edge it would roll over.
            shank = state.link_quat_wxyz[_LINK[f"{side}_knee"]] if side == sw else ik.shank_quat_wxyz
            q_ankle_ik = rot.multiply(rot.conjugate(shank), q_foot)
            if cfg.foot_yaw_control and side == sw:
                local[f"{side}_ankle"] = q_ankle_ik  # the swing foot turns to its yaw about the actual shank
                continue
            # A planted foot's twist about the shank's long axis is the one that gives its yaw about the actual
            # shank (about the IK's, the difference between the two shanks' twists would turn it against its sole's
            # friction); without foot_yaw_control every foot's twist is left where it is.
            if cfg.foot_yaw_control:
                twist_of = rot.multiply(rot.conjugate(state.link_quat_wxyz[_LINK[f"{side}_knee"]]), q_foot)
            else:
                twist_of = canonical_quat_from_model(q_cur[JOINT_NAMES.index(f"{side}_ankle")])
            swing_ik, _ = rot.swing_twist(q_ankle_ik, _UP)
            _, twist = rot.swing_twist(twist_of, _UP)
            local[f"{side}_ankle"] = rot.multiply(swing_ik, twist)
        return local, knee_angle

    # ---- 5. upper body (joint map) -----------------------------------------------------------------------------
    def _map_upper_body(self, tick: _Tick, local: dict[str, np.ndarray], hinge: dict[str, float]) -> None:
        """Upper body from the joint map; the chest keeps the operator's torso orientation in the world."""
        s = tick.s
        map_upper_body(tick.analysis.upper_local_wxyz if s is tick.sample else upper_local(s, tick.q_root_d),
                       local, hinge)

    def _reference(self, tick: _Tick, state: CharacterState, local: dict[str, np.ndarray],
                   hinge: dict[str, float]) -> ReferencePose:
        """The targets in the character's joint layout, with the LIPM map of Eq. 23 in single stance."""
        joint_pos = joint_targets(local, hinge)
        joint_pos[_BALL_JOINTS] = rot.batch_align_sign(joint_pos[_BALL_JOINTS], state.joint_pos[_BALL_JOINTS])
        lipm = None
        if tick.ch_state is not Stance.DS and not self.char_fsm.recovery_step:
            st = "left" if tick.ch_state is Stance.LS else "right"
            dh, dc = tick.com_h - tick.a_h[st], tick.com_c - tick.a_c[st]
            lipm = LipmMap(np.array([dh[0], dh[1], 0.0]), float(max(dh[2], 0.1)),
                           np.array([dc[0], dc[1], 0.0]), float(max(dc[2], 0.1)))
        # The operator's wrists relative to his pelvis in world axes, scaled, from the character's pelvis (hand tasks:
        # the hands go where his are around his body, whatever the lag of the body over the ground).
        hands = {k: state.root_pos_world + tick.scale * (tick.s.pos[f"WRIST_{v}"] - tick.p_h)
                 for k, v in _SIDE_UP.items()}
        com_d, com_vel_d = tick.com_d, tick.com_vel_d
        # (a step to where he stands holds the weight over the other foot: _rest_shift_xy)
        rest_step = self.recovery.step is not None and self.recovery.step.fixed_landing
        if self.cfg.recovery_step_free_com and self.char_fsm.recovery_step and not rest_step:
            # The character's own step: its landing is planned on the capture point of a body left to its pendulum
            # (recovery_step.py); a COM target on the operator's stance would pull the body elsewhere while the foot
            # is in the air, and the foot would land where the capture point no longer goes.
            com_d = np.array([tick.com_c[0], tick.com_c[1], tick.com_d[2]])
            com_vel_d = np.array([tick.com_vel_c[0], tick.com_vel_c[1], 0.0])
        elif self.cfg.capture_bound_sole_share > 0.0 and self._capture_bounded(tick):
            com_d, com_vel_d = self._bounded_com_target(tick, state, com_d, com_vel_d)
        elif (self.cfg.gait_capture_step_s is not None and self.cfg.capture_bound_sole_share > 0.0
              and tick.ch_state is Stance.DS):
            # His gait's double stance, where the bound above is lifted (capture_bound_in_his_gait False): the
            # capture point runs ahead of the (shrunk) soles, but no further than a step then catches
            # (capture_bound.gait_capture_margin_m).
            com_d, com_vel_d = self._bounded_com_target(tick, state, com_d, com_vel_d, self.cfg.gait_capture_step_s)
        elif self.cfg.landing_capture_bound != "off" and tick.swing is not None and tick.swing_landing_xy is not None:
            com_d, com_vel_d = self._landing_bounded_com_target(tick, state, com_d, com_vel_d)
        self.reading = MotionReading(tick.op_state, tick.analysis.features, self.char_fsm.hold_reference, tick.scale,
                                     tick.step_exceeded)
        own = tick.swing if self.char_fsm.recovery_step else None  # the swing side of a step of the character's own
        his_speed = tick.scale * float(np.hypot(tick.com_vel_h[0], tick.com_vel_h[1]))  # his COM's, scaled [m/s]
        step = self.recovery.step
        return ReferencePose(
            time_s=state.time_s, joint_pos=joint_pos, root_quat_wxyz=tick.q_root_d, pelvis_world=tick.pelvis_d,
            com_world=com_d, com_vel_world=com_vel_d, character_stance=tick.ch_state, stance_weight=tick.weights,
            ankle_world=tick.a_c, lipm=lipm, press_swing_foot=self.char_fsm.hold_reference, hand_world=hands,
            recovery_ankle_world=None if own is None else {own: tick.targets[own].copy()},
            recovery_ankle_vel_world=None if own is None or step is None else {own: step.target_vel_world},
            recovery_while_he_stands=self.char_fsm.recovery_step and self._operator_stands(tick),
            pelvis_vel_z_mps=tick.pelvis_vel_z,
            his_way_speed_mps=min(float(np.hypot(*self.way.velocity_world[:2])), his_speed),
            both_stand_still=(tick.op_state is Stance.DS and tick.his_feet_still and his_speed < _STANDING_SPEED_MPS
                             and self._rest_stance is None
                             and float(np.hypot(tick.com_vel_c[0], tick.com_vel_c[1])) < CHARACTER_STANDS_MPS),
        )

    @staticmethod
    def _ds_left_share(com: np.ndarray, ankles: dict[str, np.ndarray]) -> float:
        """Share of the weight on the left foot in double stance: COM position along the line of the ankles."""
        d = ankles["right"][:2] - ankles["left"][:2]
        n2 = float(d @ d)
        if n2 < 1e-6:
            return 0.5
        t = float((com[:2] - ankles["left"][:2]) @ d) / n2
        return 1.0 - min(max(t, 0.0), 1.0)


"""Configuration: frozen dataclasses with named, typed fields, validated when built.

Defaults are the paper's values (Cao et al. 2022) and say where they come from. Where a default departs from
the paper, the comment says how and why (see also docs/decisions.md).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stylesync.errors import ConfigError

# ../shared beside the checkout: recorded motion capture that benches and experiments use when it is present.
SHARED_DIR = Path(__file__).resolve().parents[3] / "shared"
BALANCE_METHODS = ("whole_body", "jacobian_transpose")
VIEWER_DRAW_HZ = 20.0  # default drawing rate of a viewer, independent of the control rate [Hz]


def _positive(name: str, value: float) -> None:
    if not (value > 0):
        raise ConfigError(f"{name} must be > 0, got {value!r}")


def _non_negative(name: str, value: float) -> None:
    if not (value >= 0):
        raise ConfigError(f"{name} must be >= 0, got {value!r}")


def _within(name: str, value: float, lower: float, upper: float) -> None:
    """``value`` (the field ``name``) within the closed range [``lower``, ``upper``]."""
    if not (lower <= value <= upper):
        raise ConfigError(f"{name} must be within [{lower:g}, {upper:g}], got {value}")


def _above(name: str, value: float, lower_name: str, lower: float) -> None:
    """``value`` (the field ``name``) strictly above ``lower`` (the field ``lower_name``): the upper end of a range."""
    if not (value > lower):
        raise ConfigError(f"{name} ({value!r}) must be above {lower_name} ({lower!r})")


@dataclass(frozen=True)
class PidGains:
    """Gains of one joint's PID (Eq. 13), continuous-time: tau = kp e + ki ∫e dt + kd de/dt.

    Units: kp [N·m/rad], ki [N·m/(rad·s)], kd [N·m·s/rad]. Eq. 13 prints the sum and difference without the time
    step; we read Table 3 as continuous gains (at 600 Hz the printed per-step reading would scale kd by 1/600 and
    ki by 600, which neither tracks nor stays stable).
    """

    kp: float
    ki: float
    kd: float

    def __post_init__(self) -> None:
        for n in ("kp", "ki", "kd"):
            _non_negative(f"PidGains.{n}", getattr(self, n))


def _table3() -> dict[str, PidGains]:
    # Table 3, PID controller gains per joint.
    return {
        "chest": PidGains(2500.0, 40.0, 36.0),
        "neck": PidGains(30.0, 5.0, 3.0),
        "hip": PidGains(500.0, 100.0, 20.0),
        "knee": PidGains(360.0, 72.0, 20.0),
        "ankle": PidGains(60.0, 15.0, 2.0),
        "shoulder": PidGains(60.0, 15.0, 7.0),
        "elbow": PidGains(60.0, 15.0, 1.0),
    }


@dataclass(frozen=True)
class ClockConfig:
    mocap_hz: float = 16.0  # Sec. 7.1, Kinect update rate
    control_hz: float = 133.0  # Sec. 7.1, control loop
    physics_hz: float = 600.0  # Sec. 7.1, integration step 1/600 s

    def __post_init__(self) -> None:
        for n in ("mocap_hz", "control_hz", "physics_hz"):
            _positive(f"ClockConfig.{n}", getattr(self, n))
        if self.control_hz > self.physics_hz:
            raise ConfigError(
                f"control_hz ({self.control_hz}) must not exceed physics_hz ({self.physics_hz})"
            )


@dataclass(frozen=True)
class WorldConfig:
    gravity_mps2: float = 9.8  # Sec. 7.1
    contact_stiffness_npm: float = 30000.0  # Sec. 7.1, ground damped spring
    contact_damping_nspm: float = 10000.0  # Sec. 7.1
    friction: float = 0.9  # Sec. 7.1
    # Static friction holds each contact where it began (PyBullet's friction anchors) instead of letting a foot
    # creep under a sustained sideways force below the friction limit; no force is added. Off by default: with it
    # the simulation turns micro-differences of the input into visibly different motion (docs/decisions.md).
    friction_anchor: bool = False

    def __post_init__(self) -> None:
        _positive("WorldConfig.gravity_mps2", self.gravity_mps2)
        _positive("WorldConfig.contact_stiffness_npm", self.contact_stiffness_npm)
        _non_negative("WorldConfig.contact_damping_nspm", self.contact_damping_nspm)
        _non_negative("WorldConfig.friction", self.friction)


@dataclass(frozen=True)
class FilterConfig:
    one_euro_beta: float = 1.0  # Fig. 5a, beta = 1
    one_euro_min_cutoff_hz: float = 1.0  # Fig. 5a, f_cmin = 1
    one_euro_derivative_cutoff_hz: float = 1.0  # Casiez et al. 2012 default d_cutoff
    floor_threshold_m: float = 0.01  # Sec. 4.3, floor filter threshold

    def __post_init__(self) -> None:
        _non_negative("FilterConfig.one_euro_beta", self.one_euro_beta)
        _positive("FilterConfig.one_euro_min_cutoff_hz", self.one_euro_min_cutoff_hz)
        _positive("FilterConfig.one_euro_derivative_cutoff_hz", self.one_euro_derivative_cutoff_hz)
        _non_negative("FilterConfig.floor_threshold_m", self.floor_threshold_m)


SWING_PLACEMENTS = ("capture_point", "pelvis")
SWING_LANDINGS = ("his_last_landing", "his_foot_now")
LANDING_CAPTURE_BOUNDS = ("all", "sideways", "off")


@dataclass(frozen=True)
class MotionConfig:
    # Sec. 5.1 leaves the foot-height threshold open: 4 cm on the operator's ankle heights, with hysteresis.
    stance_height_threshold_m: float = 0.04
    stance_hysteresis_m: float = 0.01
    # ... and a swing ends only once the swing ankle, at his ankle heights' double stance, moves slower than this over
    # the ground (scaled to the character): his heel rises as his swing foot comes down, and the heights call his
    # double stance while that foot still travels 0.1-0.3 m at 2-4 m/s (None: the heights alone) [m/s]
    his_landing_max_speed_mps: float | None = None
    # Late contact (Sec. 5.1): the reference is held until the character's foot touches down, at most this long.
    late_contact_timeout_s: float = 0.4
    # While a late contact holds the reference (Sec. 5.1), the pelvis and COM targets go on over the ground at the
    # desired COM velocity the hold began with (off: they stop where the operator was, braking the character)
    late_contact_keeps_momentum: bool = True
    # After the character's own step (a recovery step), Eq. 10's fraction along the heading from his rear foot to his
    # front one, on its rear and front feet, rather than from his left foot to his right on its left and right ones
    fraction_needs_feet_in_his_order: bool = True
    # The pelvis and COM targets advance at the operator's scaled COM velocity and are pulled towards the feet-anchored
    # targets of Eq. 10 with this time constant: the character keeps up with the operator over the ground
    # (docs/decisions.md, "Following his path by default"; 0: the anchored targets, `--in-place`) [s]
    reference_follows_operator_s: float = 0.5
    # ... and the targets so advanced at most this far from the anchored ones (None: no bound). Advanced at a
    # runner's speed the character cannot step at, they ran 1.7 m ahead of it, and when he stopped they came back at
    # 2-3 m/s while the COM task still pulled the body on towards them: it reached his stop too fast to stop
    # (docs/decisions.md, "Targets that ran ahead of the character") [m]
    reference_lead_max_m: float | None = 0.3
    # ... and with this time constant instead once he has stood on both feet for a second (his COM below 0.05 m/s,
    # now and over his way) and the targets have come within 5 mm of the anchored ones. With the walking time
    # constant the targets trailed the feet settling in the first second, and the stance left crept over the ground
    # (4.5 cm in 60 s on one sensor seed; docs/decisions.md, "A standing character's creep"). None:
    # reference_follows_operator_s throughout [s]
    reference_follows_standing_s: float | None = 0.0
    # Weight shift before a lift-off from standing (pose_optimization._can_lift): the operator lifts a foot after a
    # double stance of at least liftoff_after_stand_s [s] with his capture point over his other sole (within
    # liftoff_margin_m [m] of its inner edge, sideways); while the character's is further than that inwards of its
    # own other sole, or, where his is over or beyond his stance ankle (all his weight on it: a kick, a pose on one
    # leg), further than liftoff_shift_tolerance_m [m] inwards of its stance ankle, the foot stays down, at most
    # liftoff_weight_shift_s [s] (0: off), and the COM target on his stance foot moves the weight over.
    # liftoff_shift_tolerance_m None: the sole's inner edge whatever his weight shift.
    liftoff_weight_shift_s: float = 0.25
    liftoff_after_stand_s: float = 0.3
    liftoff_margin_m: float = 0.02
    liftoff_shift_tolerance_m: float | None = 0.01
    # ... and, where he stands on that foot, while the character's is further than this outwards of its stance ankle
    # (moving out: lifted there, the stance ankle has no room left to bring it back, and a kick's strike pushed it
    # out of the sole) [m] (None: no outward limit)
    liftoff_shift_outward_m: float | None = None
    # Any lift-off, from standing or in a walk (pose_optimization._can_lift): a foot that bears weight waits, as
    # above, while the character's capture point is further than this outside its other sole towards the lifting
    # foot. Standing on that sole alone, the body could only fall back onto the foot it lifts [m] (None: off).
    liftoff_capture_behind_m: float | None = 0.05
    # ... and while that holds, the foot stays down however long (False: at most liftoff_weight_shift_s, as the
    # sideways weight shift): no weight shift brings back a capture point the body is moving past, and the double
    # stance's own rules step the foot the balance chooses meanwhile (docs/decisions.md, "A lift-off onto the wrong
    # foot")
    liftoff_behind_waits: bool = True
    # A lift-off from double stance waits, however long, while the foot the operator lifts is the only one of the
    # character's on the ground (stance_fsm.CharacterStanceFsm): lifted, it would leave the body on a foot in the air
    # (docs/decisions.md, "A lift-off onto a foot in the air").
    liftoff_needs_other_foot_down: bool = True
    # A raised rear foot that still bears weight (on its toes, pose_optimization._rear_foot_bears_weight): while the
    # operator's capture point is more than this behind his stance sole's heel (the character's sole scaled to him,
    # in the heading frame) and his raised foot is behind it, his single stance is read as a double stance.
    # None: off.
    rear_foot_support_margin_m: float | None = 0.02
    # ... and once read so, until his capture point is less than the margin minus this behind the heel: a slow,
    # low stride (a sneaky walk) keeps his capture point within a centimetre of the margin for a few tenths of a
    # second, and read without a band his stance flickered between double and single every 0.02-0.1 s, each flicker
    # a lift-off and a landing of his (docs/decisions.md, "His stance read through a band") [m]
    rear_foot_support_hysteresis_m: float = 0.02
    # ... but not while his way over the ground (operator_way.py, the last second's, in his own heading frame) goes
    # backwards at least this fast: the raised rear foot steps, as in a backward walk, where his capture point lies
    # behind the stance heel at every step (docs/decisions.md, "A backward walk"). None: whatever his way [m/s].
    rear_foot_stepping_way_mps: float | None = 0.3
    # Early contact (Sec. 5.1) only counts once the swing has lasted this long (a lifting foot still touches).
    min_swing_s: float = 0.12
    stance_hip_weight_w0: float = 0.5  # Eq. 11 weight w0 (not given in the paper)
    swing_hip_cd: float = 0.0  # Eq. 12, Sec. 7.2 sets c_d = 0
    swing_hip_cv: float = 0.0  # Eq. 12, Sec. 7.2 sets c_v = 0
    max_swing_foot_lift_m: float = 0.25  # clamp of the scaled swing-ankle height above the ground [m]
    # The feet's yaw about the shank (the ankle is a ball joint; pose_optimization.py): a swing foot turns to its
    # target yaw (the operator's foot's; a recovery step's, the heading), and an unloaded planted foot keeps the yaw
    # it had when it last pressed the ground. Off: the twist is left where it is, and the feet drifted to 90-180°
    # from the body (docs/decisions.md, "The feet's yaw").
    foot_yaw_control: bool = True
    # Where the swing foot goes, horizontally (pose_optimization.py): the operator's foot relative to his capture
    # point, scaled, from the character's capture point ("capture_point"), or relative to his pelvis from the
    # character's pelvis ("pelvis", no balance feedback, as Sec. 7.2's c_d = c_v = 0).
    swing_placement: str = "capture_point"
    # With "capture_point", the landing's offset from the character's capture point is the one his foot had from his
    # when it last came down on that side ("his_last_landing"; the other side's, mirrored, until he has landed on
    # this one; before his first landing, the present offset of his swing foot), and the swing goes from where the
    # character's foot lifted off to that landing as his swing proceeds; or ("his_foot_now") the offset his swing
    # foot has from his capture point now, from a start placed relative to the stance foot as his is to his. During
    # his swing his foot is far behind his capture point (0.7 m at his lift-off in the built-in walk): with
    # "his_foot_now" the swing went back by up to 0.4 m before it came forward, and the character walked backwards
    # (docs/decisions.md, "A character that walked backwards").
    swing_landing: str = "his_last_landing"
    # With "capture_point", where the swing foot lands relative to the character's capture point, in the heading
    # frame: at least this far behind it (a foot landing ahead of it stops the body and, once the rear foot
    # lifts, drops it backwards; the linear inverted pendulum's steady gait lands about step / (e^(ωT) - 1)
    # behind, 0.1 m at this character's walking step and time) [m]
    step_behind_capture_point_m: float = 0.1
    # ... and, with swing_landing "his_last_landing", at most this far behind it: a runner's foot lands 0.6-1 m
    # behind his capture point, and copied from the smaller character's the body ran away from its feet and fell in
    # the rest after the short runs (docs/decisions.md, "A character that walked backwards") (None: no bound) [m]
    step_behind_capture_point_max_m: float | None = 0.3
    # and this far outside it, sideways (min, max): a foot further out throws the body back harder than the
    # next step can catch, and the sway grows from step to step [m]
    step_outside_capture_point_m: tuple[float, float] = (0.0, 0.04)
    # With "capture_point", a swing that neither he nor the character needs to land (his capture point within the
    # sole he stands on, the character's within its own: a kick, a raised leg) follows his foot relative to the
    # stance foot, scaled, instead of going to the landing: the strike of a kick is his style (off: every swing goes
    # from its lift-off to its landing, and a kick only lifts the foot and puts it down).
    free_swing: bool = False
    # Recovery steps (motion/recovery_step.py): while the operator stands, the character steps on its own when its
    # capture point is further than the margin outside the support polygon of its soles [m]; the step's nominal
    # swing time [s] and height [m]; the double stance kept after one before another, and the time the operator
    # must have stood before the first [s]. At 0.1 s a foot that had just landed could unload again before the next
    # step began, leaving only the sole that cannot catch the body (docs/decisions.md, "The double stance between
    # two recovery steps").
    recovery_steps: bool = True
    recovery_step_margin_m: float = 0.02
    recovery_swing_s: float = 0.2
    # Step timing: a recovery step lands when its capture landing would leave the leg's reach
    # (RecoveryStepper.time_to_reach_limit_s), if that is sooner than recovery_swing_s, but no sooner than this
    # after its start: a step that lands later lands short of the capture point, and the next one starts with it
    # outside its support (docs/decisions.md, "Recovery steps that land before the capture point leaves the
    # reach"). None: every recovery step takes recovery_swing_s [s].
    recovery_swing_min_s: float | None = 0.1
    recovery_step_height_m: float = 0.05
    recovery_min_stance_s: float = 0.03
    # A step from double stance does not stand on a foot that bears less than this share of the two soles' normal
    # force while the COM moves away from its ankle: lifted, the loaded foot left the body on neither sole (the
    # humanoid3d jump, seed 1: both soles bore nothing for 0.13 s and it fell; docs/decisions.md, "A step of its
    # own onto an unloaded foot"). A foot the body moves onto stands, loaded or not: one just landed ahead is about
    # to bear it (None: by the capture point alone) [-]
    recovery_stance_min_load_share: float | None = None
    # A recovery step's foot target comes down to the ground at this share of recovery_swing_s (and is then aimed
    # below it until the foot touches): the foot trails its target, and aimed at the ground only at the swing's end
    # it touched down 0.03 s late at the median and 0.1 s late or more on one step in five, while the capture point
    # ran on beyond the landing planned for the swing's end (docs/decisions.md, "Recovery steps that touch down on
    # time") [-]
    recovery_touchdown_share: float = 0.9
    # A swing taken over in the air (RecoveryStepper.take_over) keeps its foot at least recovery_step_height_m up
    # until the foot itself has come this share of the way from where it was taken over to its landing, and comes
    # down over the rest: lowered with the target's travel, the foot, trailing its target, came down beside the
    # stance foot, short of the landing, and a step of the other foot followed (docs/decisions.md, "A taken-over
    # swing that comes down short"). None: lowered along the target's travel [-]
    recovery_takeover_clearance_share: float | None = None
    # A swing taken over with its ankle less than this above its height on the ground (taken over at his lift-off,
    # before the foot has risen: the reach rule in a fast walk, a clip's held last frame) is a step from the ground,
    # its foot up by recovery_step_height_m and down, not a foot in the air lowered from where it is: lowered from the
    # ground, the foot slid 0.9 m along it to its landing, loaded, touched down beside the stance foot, and the own
    # steps after it ran the body away (docs/decisions.md, "A swing taken over on the ground"). None: every taken-over
    # swing is lowered from where its foot is [m]
    recovery_takeover_low_foot_m: float | None = 0.05
    # ... and it has landed once its horizontal travel is over and the lowest corner of its sole is within this of
    # the ground, not only once it presses with CONTACT_FORCE_N: a foot that came down on a corner, tilted, rested
    # there with less than that while the stance leg, straight, held the pelvis above its target, and the body ran
    # on over one foot (docs/decisions.md, "A recovery step that has reached the ground") (None: by the force
    # only) [m]
    recovery_landing_gap_m: float | None = 0.003
    # A step of the character's own whose foot touches the ground before its landing is due (before it has covered
    # its way over the ground, recovery_step.HORIZONTAL_SHARE of its swing time), more than a foot's length short of
    # the landing, has scuffed it, not landed: the step goes on. Traced on CMU-dev 05_01 (seed 8): a swing taken over
    # 0.03 s after his lift-off, its foot 1-2 cm up, touched 0.12 s after it, 0.55 m short of its landing, and ended
    # there; the next step of its own, from a foot that far behind the capture point, could not catch the body, and a
    # chain of them ran it to 2.4 m/s and down (docs/decisions.md, "An own step's foot that scuffs the ground"). Off
    # by default: over the suite's seeds 0-11 as many runs fall as without it (the spinning kick for the walks).
    own_step_scuff_before_due: bool = False
    # A recovery step lands its ankle at most this share of the leg's length from the stance ankle (the pelvis lowered
    # as the leg needs, recovery_landing_reach): at 0.6 the steps that stop a walk landed short of the capture point,
    # and each left the body faster (docs/decisions.md, "Longer recovery steps") [-]
    recovery_step_reach_share: float = 0.75
    # A recovery step may land across the stance foot (a crossover step) where its ankle lands at least this far ahead
    # of or behind the stance ankle, in the heading frame; nearer, at least 1.2 hip half-widths outwards of it (None:
    # never across). Kept on its own side, a swing foot could only land beside the stance foot when the capture point
    # left the stance sole on the far side, and the other foot's step out came too late (docs/decisions.md,
    # "Crossover recovery steps") [m]
    recovery_cross_clear_m: float | None = 0.15
    # A recovery step's landing across the stance foot but not clear of it goes to the nearer of the two places off
    # it: outwards beside the stance foot, or the crossover clearance ahead of or behind it. Always outwards, a
    # landing planned just short of the clearance (a capture point ahead on the stance foot's far side) went to the
    # wrong side of the stance foot (docs/decisions.md, "A crossover step just short of its clearance")
    recovery_cross_nearest: bool = True
    # ... and the crossover clearance and the outward side are taken in the stance sole's own yaw frame, where the
    # sole is, instead of the heading frame, which turns with the operator's root (by 40° in 0.2 s in a spin) while the
    # planted sole does not
    recovery_cross_stance_frame: bool = True
    # With one sole on the ground, no recovery step of the other foot while it is in the air where, landed as it is,
    # it leaves the predicted capture point no further outside the support than its step would: it is landing where
    # the body goes, and its step, within reach of the sole on the ground, took it back from there
    # (docs/decisions.md, "A landing foot is left to land")
    recovery_landing_foot_waits: bool = True
    # ... also while the operator is on one foot but the character, its step for his counted as taken (early
    # contact), stands on both and waits for his next change
    recovery_while_step_counted: bool = True
    # Step timing (motion/recovery_step.py): a swing of the operator's that has lasted this many times his usual
    # swing time, while the character's capture point is outside its stance sole by more than the margin, is
    # landed by the balance (a recovery step takes it over) [-]
    recovery_swing_overrun: float = 1.5
    # ... and at once when the operator stops on this step (he stands over his soles) and the landing his step gives
    # would not catch the character's capture point: the stopping landing (pose_optimization.py) is then reached in
    # a recovery step's time, not in his slower lowering of the foot
    recovery_on_stopping_step: bool = True
    # ... and at once when, held to his timing, the swing would land too late: the capture point, where it will be at
    # his usual landing time (the centre of pressure held at the stance sole's point nearest to it), is further from
    # the stance ankle than a recovery step reaches (recovery_step_reach_share). A character faster than its operator
    # vaulted over its stance foot and sank while his slower swing went on (docs/decisions.md, "Landing before the
    # capture point is out of reach")
    recovery_on_reach_limit: bool = True
    # ... where his swing has outlasted his usual swing time (a pose on one leg, a clip's held last frame, his raised
    # foot lowered slowly), that prediction is made a recovery step's swing time (recovery_swing_s) ahead, not for
    # now: his landing is no longer due at any known time, and the soonest the balance itself can land the foot is
    # a recovery step's swing from now. Predicted for now, the capture point ran out of reach in the single stance
    # before the rule fired (docs/decisions.md, "A swing past its usual time: when it can land")
    recovery_overdue_swing_horizon: bool = True
    # ... and while a late contact holds the reference (Sec. 5.1: he has landed, the character's swing foot has not):
    # by the same rules, the held swing becomes the character's own step (off: a held swing lands where his did,
    # whatever the capture point does, for up to late_contact_timeout_s)
    recovery_in_late_contact: bool = False
    # ... and in the character's double stance, whatever the operator does: once its capture point has been outside
    # the support polygon of its soles (by more than the margin) for this many times his usual double stance, a
    # recovery step (he walks on, or stands on one foot, while the character waits for a lift-off of his that
    # comes too late for it; 0: off) [-]
    recovery_double_stance_overrun: float = 1.5
    # ... and at once when waiting for his next lift-off (the rest of his double stance, or the rest of his swing and a
    # double stance of his usual length) and then a recovery step's swing would leave the capture point out of a
    # recovery step's reach whichever foot stands, while a recovery step now captures it: the wait is his gait's,
    # and the character's capture point runs out of reach before it ends (with the overrun, off at 0;
    # docs/decisions.md, "A double stance that waits out of reach")
    recovery_ds_on_reach_limit: bool = True
    # ... and at once as well where no recovery step now captures it either: a capture point already beyond one
    # step's reach only runs further out while the character waits on both feet, and a step as far as it reaches
    # leaves the least for the next (False: only where a step now captures it; docs/decisions.md, "A double stance
    # beyond a step's reach")
    recovery_ds_beyond_reach: bool = True
    # ... at once where the capture point has left that polygon behind: the outward direction from the polygon's
    # nearest point to the capture point has a share below minus this of the heading's forward axis (a step of an
    # operator walking forwards can never catch it; docs/decisions.md, "A capture point behind both feet"; None: off)
    recovery_step_behind_cos: float | None = 0.7
    # During a recovery step the COM task holds the character's own COM state (no pull towards the operator's
    # stance): the body moves as the landing's capture-point prediction assumes
    recovery_step_free_com: bool = True
    # When a recovery step's foot is due to go down, the pelvis is lowered as far as the leg needs to reach its
    # landing from where the hip is (a landing at the leg's full reach otherwise hovers above the ground while the
    # body runs on)
    recovery_landing_reach: bool = True
    # A foot that must land lowers the pelvis target to no less than this share of the leg's reach above the foot's
    # target: lower, the foot cannot be brought within reach, and the legs could not hold the body there. Measured
    # from an operator's pelvis target far from the body (0.45 m to the side of it in the kick in place, 0.87 m
    # ahead of it in a walk's rest), the foot was out of reach, and the pelvis target dropped to the foot's own
    # height (docs/decisions.md, "A pelvis target out of a landing foot's reach"; 0: no floor) [-]
    landing_pelvis_floor_share: float = 0.6
    # ... but a foot whose sole's lowest corner is within this of the ground is on it, pressing or not, and needs no
    # lowering: a supporting foot resting unloaded (0-4 N, below CONTACT_FORCE_N) read as one that must land, and the
    # pelvis target dropped to its floor (0.3 m) and back on alternate control ticks while the stance knee folded
    # (docs/decisions.md, "A foot on the ground that must land"; None: by its pressing alone; 0.003 in `--follow-path`:
    # by default the standing character drifted 4.2 cm in 60 s with it, 1.3 cm without) [m]
    landing_reach_ground_gap_m: float | None = None
    # The pelvis target lowered for a foot that must land comes down at most at this speed from the last control
    # tick's: the lowering to a foot out of reach came as one step of 0.3-0.4 m within a tick at landings of the
    # humanoid3d spinning kick (docs/decisions.md, "The pelvis target's steps within a control tick"; None: at
    # once) [m/s]
    landing_pelvis_descent_mps: float | None = None
    # As his swing goes, the pelvis target comes down towards the height from which the swing foot reaches its
    # landing on the ground (the landing reach, from the target's hip), by the swing's progress (a smooth step over
    # his usual swing time), instead of all at once when a late contact holds the reference: there it dropped by up
    # to 0.11 m within one control tick, the stance leg's joint targets jumped with it, and the whole-body QP planned
    # a brake of 90-140 N that no task asked for (docs/decisions.md, "A late contact's brake, attributed"). False:
    # lowered only for a foot that must land now (the scenario tests traced before it pin it off).
    swing_landing_within_reach: bool = True
    # The pelvis target (Eq. 9) no higher than this share of the leg's length reaches above each planted stance foot
    # (hip to ankle, from the target's hip). His pelvis, scaled, can sit above what the character's straight legs
    # reach (CMU 02_01: 0.94 m against 0.88 m): the stance leg is then held straight, and the lowering above for a
    # foot that must land came as one step of the target (11 cm at a late contact), which the stance knee took by
    # folding and the walk by braking (docs/decisions.md, "The pelvis target within the stance legs' reach")
    # (None: not bounded) [-]
    pelvis_stance_reach_share: float | None = None
    # An operator's swing is aimed within the leg's horizontal reach of the swing hip as it is, with the pelvis
    # lowered to that floor (sqrt(1 - floor²) of the reach): a runner's foot, placed as his is relative to his
    # capture point and his stance foot, was aimed up to 2.3 m from the slower character's hip (CMU-dev 09_06); in
    # the humanoid3d run such a foot hovered out of reach for half a second under the late contact's hold while the
    # body fell over its stance foot (docs/decisions.md, "A swing aimed out of the leg's reach") (False: aimed where
    # the placement puts it)
    swing_within_reach: bool = True
    # A recovery step's landing is planned on the capture point of the body with the swing leg carried along by the
    # pelvis (MassProperties.com_velocity_carried): the leg's own swing moves the whole body's capture point with
    # the foot, and the ground stops that motion when the foot lands. Planned on the whole body's, the landing
    # chased the capture point its own swing moved outwards (docs/decisions.md, "Recovery steps that land")
    recovery_landing_without_swing: bool = True
    # The COM target asks for no capture point outside the soles the character stands on, each shrunk to this share
    # of its length and width about its centre, in double stance, and in single stance while the operator balances
    # over his stance sole (motion/capture_bound.py; 0: off) [-]
    capture_bound_sole_share: float = 0.8
    # Opt-in: in single stance (not the character's own step), the COM target's capture point is kept where the
    # planned landing catches it when the swing foot lands (MotionOptimizer._landing_bounded_com_target): "all",
    # only "sideways" (across the heading), or "off". Measured on the development suite, neither gains beyond the
    # spread between seeds, and "all" halves the walks' progress along the operator's path (docs/decisions.md).
    landing_capture_bound: str = "off"
    # In the operator's double stance, the desired COM velocity along his scaled COM velocity is not below
    # the character's own, up to his (motion/double_stance_momentum.py): a character slower than its operator is not
    # braked at each double stance of a walk. Only while his COM moves from one of his feet towards the other
    # (double_stance_momentum.GAIT_AXIS_DEG), and while the character's capture point is within this distance
    # outside the support polygon of its feet on the ground: a body already beyond what its feet can stop is braked
    # as before. The walks then cover more of his way with as many runs completing, but the built-in walk's
    # character steps on its own and falls out of step with him (docs/decisions.md, "Momentum kept through a double
    # stance"). 0.1 m is the measured setting; None: off (`--in-place`) [m].
    double_stance_keeps_momentum_m: float | None = 0.1
    # In the character's double stance the COM target's capture point is kept within its soles
    # (capture_bound_sole_share); False: not while the operator walks from one foot onto the other
    # (double_stance_momentum.moves_between_feet), whose capture point runs ahead of his front foot.
    capture_bound_in_his_gait: bool = False
    # ... and where it is False: in his gait's double stance the COM target's capture point runs ahead of the
    # soles by at most what a step this long from now catches within a recovery step's reach
    # (capture_bound.gait_capture_margin_m: reach e^(-ω T)); None: unbounded there [s].
    gait_capture_step_s: float | None = 0.3
    # While the operator is on one foot of his gait (he goes somewhere, his COM moving his way, his capture point
    # outside the sole he stands on) and the character on both (its step landed before his), the COM target's capture
    # point is kept within its soles; False: there too the bound is his gait's double stance's (gait_capture_step_s;
    # none where that is None), not the soles', which braked the character to a stop before each of his landings
    # (docs/decisions.md, "A step landed before his").
    capture_bound_before_his_landing: bool = False
    # While the operator walks (his capture point outside his soles), a recovery step lands with the capture point
    # this far ahead of its ankle instead of on its sole's trailing edge: a step that walks on with him rather than
    # one that stops the body (recovery_step.capture_landing). None: every recovery step stops it [m].
    recovery_walk_on_m: float | None = 0.1
    # The walk-on above along the operator's way over the ground (his COM's direction of motion), as far as the
    # capture point diverges that way; across it the step catches the body on its ankle (recovery_step.WalkOn).
    # False: along the capture point's own divergence, which carries a sideways drift on from step to step.
    recovery_walk_on_his_way: bool = True
    # ... and only while his COM moves now at least gait_min_way_speed_mps fast as well (the way's average trails a
    # stop by its time constant: a run's own steps walked on after he stopped)
    recovery_walk_on_needs_motion_now: bool = False
    # ... and only as far as his way goes forwards: the walk-on times the share of his way along his heading's
    # forward axis (none where he goes sideways or backwards, and the step stops the body). Walked on sideways, a
    # dance's own steps, which cannot cross or lengthen as a forward stride does, ran the body away from its feet
    # at 1-2 m/s (docs/decisions.md, "Own steps that walk on sideways"; False: along his way whichever way it goes)
    recovery_walk_on_forward: bool = False
    # The operator's way over the ground: his scaled COM velocity averaged with this time constant, longer than a
    # step (motion/operator_way.py) [s]. While its speed is below gait_min_way_speed_mps he goes nowhere (a sway on
    # the spot, a dance): his double stance is no gait's (double_stance_keeps_momentum_m and
    # capture_bound_in_his_gait do not apply) and the character's own steps stop the body (no walk-on). None: any
    # double stance whose COM moves between his feet is a gait's [m/s].
    operator_way_time_s: float = 1.0
    gait_min_way_speed_mps: float | None = 0.3
    # His pelvis's upward speed handed on to the controller (ReferencePose.pelvis_vel_z_mps, a share of it tracked on
    # both feet, WholeBodyConfig.pelvis_rate_share) only while he stands on both feet and began the rise on them: a
    # jump's push, not a run's stride (his FSM passes through double stance in its flight) nor a vault onto one foot
    # (motion/his_rise.py). False: his pelvis's rise whatever his stance.
    rise_begun_on_both_feet: bool = True
    # Following the operator over the ground (motion/path_feedback.py): the swing's landing relative to the
    # character's capture point is moved so that a step removes this share of the capture point's error from his,
    # scaled onto the character's path from where both started (the divergent component of motion: 1 removes it
    # in one step, above 2 it grows), the move at most path_feedback_max_m. 0: off [-], [m].
    path_feedback_share: float = 0.5
    path_feedback_max_m: float = 0.2
    # Following the operator over the ground by the targets (motion/path_feedback.py, PathReference.target_pull_xy):
    # the pelvis and COM targets of Eq. 10 are moved this share of the way from the COM target to his COM, scaled
    # onto the character's path from where both started, the move at most path_target_max_m. The COM task sets the
    # character's speed over the ground, and targets anchored on its own feet carry every step it falls short of
    # his as a lag (docs/decisions.md, "Targets on his path"). 0: off [-], [m].
    path_target_share: float = 1.0
    path_target_max_m: float = 0.3
    # ... all of that pull while his way over the ground (motion/operator_way.py, scaled) is at most
    # path_target_fade_from_mps fast, none from path_target_fade_to_mps on, in proportion between: the character's
    # gait at his cadence tops out at about 0.75 m/s (docs/decisions.md, "How fast an operator the character keeps up
    # with"), and a pull towards a faster operator only makes it outrun its own steps, which a step of its own then
    # lands early, out of step with his (docs/decisions.md, "The targets on his path below the gait's top speed").
    # None: the pull at every speed [m/s].
    path_target_fade_from_mps: float | None = 0.5
    path_target_fade_to_mps: float = 0.7
    # ... and all of it for path_target_step_hold_s after he last stood on one foot, none from twice that on, in
    # proportion between: the character follows his path by its steps, and an operator who takes none (he stands,
    # jumps with both feet) gives it none to follow with (docs/decisions.md, "The targets on his path below the
    # gait's top speed"; None: whether he steps or not) [s]
    path_target_step_hold_s: float | None = 0.5
    # ... and of that, the share of the last operator_way_time_s in which his COM went along his way over the ground
    # (operator_way.py's average), at least path_target_along_min_mps fast and within the angle whose cosine is
    # path_target_along_cos: a dance's sway, a spin's circle or a turn on the spot is followed by turning and
    # stepping in place, not pulled along (docs/decisions.md, "The targets on his path below the gait's top speed";
    # None: along his way or not) [-], [m/s]
    path_target_along_cos: float | None = 0.5
    path_target_along_min_mps: float = 0.2
    # Steps to where he stands (motion/rest_step.py; docs/decisions.md, "Steps to where he stands"): once he has stood
    # still for rest_step_after_s and his feet are still, each of the character's feet has his foot's place on its
    # path; the foot that a step brings the most nearer its place, by rest_step_min_m at least, steps there on its own
    # (at most rest_step_reach_m from where it lifts off and from the other foot, its swing rest_step_swing_s long),
    # after the weight has moved over the other foot (the COM target moved there, and back after the landing, at
    # rest_step_shift_mps). None: the character stays where it stopped [m], [s], [m/s], [s], [m].
    rest_step_min_m: float | None = 0.1
    rest_step_after_s: float = 0.5
    rest_step_shift_mps: float = 2.0
    rest_step_swing_s: float = 0.4
    rest_step_reach_m: float = 0.35
    # An operator's ankle higher than this share of his leg above his floor (the lowest his ankles have been, rising
    # slowly) bears no weight (on the ball of his foot an ankle rises by at most its distance to the ball, about
    # 0.15 m for a 0.9 m leg): on a stance foot that high he is in the air, and the pelvis height of Eq. 9 is
    # measured from the height that ankle had when it left the ground, not from the foot in the air. Measured from
    # it, the built-in spin's leap (his feet 1.6 m up, above his head) put the character's pelvis target below the
    # ground, and the stance leg folded (docs/decisions.md, "An operator in the air"; None: from the foot wherever
    # it is) [-]
    airborne_ankle_height_leg: float | None = 0.2
    # ... and so is it where Eq. 10 is anchored on both his feet (his double stance, or the character's while a late
    # contact holds the reference): from the mean of his two ankles' ground heights, not of the ankles wherever they
    # are. From the ankles, his kick in the air while the character stood on both feet dropped the pelvis target by
    # 0.67 m for a control tick (the humanoid3d spinning kick; docs/decisions.md, "The pelvis target's steps within a
    # control tick"; False: from the ankles)
    ds_anchor_ground_height: bool = False
    # The pelvis target of Eq. 9 no lower than this while he crouches, his trunk upright (pose_optimization.
    # CROUCH_TRUNK_MAX_DEG; lying, crawling or rolling he is followed to the ground): the session counts a pelvis below
    # 0.5 m as a fall (session.FALL_ROOT_HEIGHT_M), and a character that followed his deepest crouch there (his pelvis
    # 0.4 m up, scaled) was counted fallen while it stood on both feet (docs/decisions.md, "A crouch deeper than the
    # fall height"). None: as deep as he goes [m]
    pelvis_min_height_m: float | None = 0.6
    # A recording started standing (both feet down, slower than gait_min_way_speed_mps) with the character's capture
    # point outside its soles shrunk to this share of their size about their centres (model/sole.sole_corners_in_foot):
    # its feet are set down under it, his pelvis kept (motion/initial_state.standing_start_shift; docs/decisions.md, "A
    # standing start over the toes"). Well inside the capture bound's (capture_bound_sole_share): a start at that edge
    # drifted over it. None: his ankles' places from his pelvis, wherever that leaves the capture point [-]
    standing_start_sole_share: float | None = 0.5
    # ... and such a start at rest: over its first two frames a standing person's velocity is the sensor's noise
    # (5 mm at 16 Hz, about 0.1 m/s; CMU-dev 10_04, seed 0: 0.20 m/s). False: with the velocities of its first two
    # frames as any recording (docs/decisions.md, "A standing start over the toes")
    standing_start_at_rest: bool = True
    # His pelvis for Eq. 9-10 (the pelvis height and the pelvis target over the ground, the swing foot's and the
    # hands' places relative to it): the midpoint of his hip joints, where the character's root is on its own body
    # (processing/body_parameters.hip_centre_world), whichever place his skeleton gives its pelvis joint; False: that
    # joint, which CMU's BVH files put 0.1 m above the hip joints (the pelvis target then 0.09 m above where his legs
    # put his, beyond straight legs' reach) and the CMU-dev files 0.03 m below (docs/decisions.md, "His pelvis at his
    # hip joints"; `--pelvis-joint`, PELVIS_JOINT_MOTION, the settings before 2026-12-06).
    pelvis_from_hip_joints: bool = True
    # The pelvis target of Eq. 9 this much higher than his, scaled (negative: lower): a character whose stance leg
    # is as straight as his has no reach left for the step his speed needs, its flat feet having none of the
    # heel-to-toe roll that lengthens his (docs/decisions.md, "His pelvis at his hip joints"; 0 with
    # `--pelvis-joint`) [m]
    pelvis_height_offset_m: float = -0.07
    # ... in full while his scaled COM speed is at least this, in proportion below it (standing, none: a standing
    # character lowered by it drifted 2.2-2.3 cm in 60 s against 1.4 and 0.6 cm) [m/s]
    pelvis_offset_full_speed_mps: float = 0.5
    # ... and none up to this speed of his (between the two, in proportion) [m/s]
    pelvis_offset_start_speed_mps: float = 0.0

    def __post_init__(self) -> None:
        lo, hi = self.step_outside_capture_point_m
        if not lo <= hi:
            raise ConfigError(f"MotionConfig.step_outside_capture_point_m must be (min, max), got {(lo, hi)}")
        _non_negative("MotionConfig.step_behind_capture_point_m", self.step_behind_capture_point_m)
        if self.his_landing_max_speed_mps is not None:
            _positive("MotionConfig.his_landing_max_speed_mps", self.his_landing_max_speed_mps)
        if (self.step_behind_capture_point_max_m is not None
                and self.step_behind_capture_point_max_m < self.step_behind_capture_point_m):
            raise ConfigError(f"MotionConfig.step_behind_capture_point_max_m ({self.step_behind_capture_point_max_m}) "
                              f"must be at least step_behind_capture_point_m ({self.step_behind_capture_point_m})")
        if self.swing_landing not in SWING_LANDINGS:
            raise ConfigError(f"MotionConfig.swing_landing must be one of {', '.join(SWING_LANDINGS)}, "
                              f"got '{self.swing_landing}'")
        if self.landing_capture_bound not in LANDING_CAPTURE_BOUNDS:
            raise ConfigError(f"MotionConfig.landing_capture_bound must be one of "
                              f"{', '.join(LANDING_CAPTURE_BOUNDS)}, got '{self.landing_capture_bound}'")
        if self.swing_placement not in SWING_PLACEMENTS:
            raise ConfigError(f"MotionConfig.swing_placement must be one of {', '.join(SWING_PLACEMENTS)}, "
                              f"got '{self.swing_placement}'")
        _positive("MotionConfig.stance_height_threshold_m", self.stance_height_threshold_m)
        if self.rear_foot_stepping_way_mps is not None:
            _non_negative("MotionConfig.rear_foot_stepping_way_mps", self.rear_foot_stepping_way_mps)
        _non_negative("MotionConfig.rear_foot_support_hysteresis_m", self.rear_foot_support_hysteresis_m)
        if self.airborne_ankle_height_leg is not None:
            _positive("MotionConfig.airborne_ankle_height_leg", self.airborne_ankle_height_leg)
        if self.pelvis_min_height_m is not None:
            _positive("MotionConfig.pelvis_min_height_m", self.pelvis_min_height_m)
        _non_negative("MotionConfig.pelvis_offset_start_speed_mps", self.pelvis_offset_start_speed_mps)
        _above("MotionConfig.pelvis_offset_full_speed_mps", self.pelvis_offset_full_speed_mps,
               "pelvis_offset_start_speed_mps", self.pelvis_offset_start_speed_mps)
        _non_negative("MotionConfig.recovery_step_margin_m", self.recovery_step_margin_m)
        if self.double_stance_keeps_momentum_m is not None:
            _non_negative("MotionConfig.double_stance_keeps_momentum_m", self.double_stance_keeps_momentum_m)
        if self.recovery_cross_clear_m is not None:
            _non_negative("MotionConfig.recovery_cross_clear_m", self.recovery_cross_clear_m)
        _within("MotionConfig.capture_bound_sole_share", self.capture_bound_sole_share, 0.0, 1.0)
        if self.standing_start_sole_share is not None:
            _within("MotionConfig.standing_start_sole_share", self.standing_start_sole_share, 0.0, 1.0)
        _positive("MotionConfig.recovery_swing_s", self.recovery_swing_s)
        if self.gait_capture_step_s is not None:
            _positive("MotionConfig.gait_capture_step_s", self.gait_capture_step_s)
        if self.recovery_swing_min_s is not None:
            _positive("MotionConfig.recovery_swing_min_s", self.recovery_swing_min_s)
        if self.recovery_landing_gap_m is not None:
            _positive("MotionConfig.recovery_landing_gap_m", self.recovery_landing_gap_m)
        _positive("MotionConfig.operator_way_time_s", self.operator_way_time_s)
        if self.gait_min_way_speed_mps is not None:
            _non_negative("MotionConfig.gait_min_way_speed_mps", self.gait_min_way_speed_mps)
        if not 0.0 < self.recovery_touchdown_share <= 1.0:
            raise ConfigError(f"MotionConfig.recovery_touchdown_share must be within (0, 1], "
                              f"got {self.recovery_touchdown_share}")
        _non_negative("MotionConfig.recovery_step_height_m", self.recovery_step_height_m)
        clearance = self.recovery_takeover_clearance_share
        if clearance is not None and not 0.0 <= clearance < 1.0:
            raise ConfigError(f"MotionConfig.recovery_takeover_clearance_share must be within [0, 1), "
                              f"got {self.recovery_takeover_clearance_share}")
        if self.recovery_takeover_low_foot_m is not None:
            _non_negative("MotionConfig.recovery_takeover_low_foot_m", self.recovery_takeover_low_foot_m)
        if self.pelvis_stance_reach_share is not None and not 0.0 < self.pelvis_stance_reach_share <= 1.0:
            raise ConfigError(f"MotionConfig.pelvis_stance_reach_share must be within (0, 1] or None, got "
                              f"{self.pelvis_stance_reach_share}")
        if self.landing_pelvis_descent_mps is not None:
            _positive("MotionConfig.landing_pelvis_descent_mps", self.landing_pelvis_descent_mps)
        if self.landing_reach_ground_gap_m is not None:
            _positive("MotionConfig.landing_reach_ground_gap_m", self.landing_reach_ground_gap_m)
        _within("MotionConfig.landing_pelvis_floor_share", self.landing_pelvis_floor_share, 0.0, 1.0)
        _non_negative("MotionConfig.recovery_min_stance_s", self.recovery_min_stance_s)
        _positive("MotionConfig.recovery_step_reach_share", self.recovery_step_reach_share)
        _positive("MotionConfig.recovery_swing_overrun", self.recovery_swing_overrun)
        _non_negative("MotionConfig.recovery_double_stance_overrun", self.recovery_double_stance_overrun)
        if self.recovery_step_behind_cos is not None and not -1.0 <= self.recovery_step_behind_cos <= 1.0:
            raise ConfigError("MotionConfig.recovery_step_behind_cos must be within [-1, 1] or None, "
                              f"got {self.recovery_step_behind_cos}")
        _non_negative("MotionConfig.reference_follows_operator_s", self.reference_follows_operator_s)
        if self.reference_lead_max_m is not None:
            _non_negative("MotionConfig.reference_lead_max_m", self.reference_lead_max_m)
        if self.reference_follows_standing_s is not None:
            _non_negative("MotionConfig.reference_follows_standing_s", self.reference_follows_standing_s)
        _non_negative("MotionConfig.path_feedback_share", self.path_feedback_share)
        _non_negative("MotionConfig.path_feedback_max_m", self.path_feedback_max_m)
        _within("MotionConfig.path_target_share", self.path_target_share, 0.0, 1.0)
        _non_negative("MotionConfig.path_target_max_m", self.path_target_max_m)
        if self.path_target_along_cos is not None:
            _within("MotionConfig.path_target_along_cos", self.path_target_along_cos, -1.0, 1.0)
        _non_negative("MotionConfig.path_target_along_min_mps", self.path_target_along_min_mps)
        if self.path_target_step_hold_s is not None:
            _positive("MotionConfig.path_target_step_hold_s", self.path_target_step_hold_s)
        if self.path_target_fade_from_mps is not None:
            _non_negative("MotionConfig.path_target_fade_from_mps", self.path_target_fade_from_mps)
            _above("MotionConfig.path_target_fade_to_mps", self.path_target_fade_to_mps,
                   "path_target_fade_from_mps", self.path_target_fade_from_mps)
        if self.rest_step_min_m is not None:
            _non_negative("MotionConfig.rest_step_min_m", self.rest_step_min_m)
        _non_negative("MotionConfig.rest_step_after_s", self.rest_step_after_s)
        for n in ("rest_step_shift_mps", "rest_step_swing_s", "rest_step_reach_m"):
            _positive(f"MotionConfig.{n}", getattr(self, n))
        for n in ("liftoff_weight_shift_s", "liftoff_after_stand_s", "liftoff_margin_m"):
            _non_negative(f"MotionConfig.{n}", getattr(self, n))
        if self.liftoff_shift_outward_m is not None:
            _non_negative("MotionConfig.liftoff_shift_outward_m", self.liftoff_shift_outward_m)
        if self.liftoff_shift_tolerance_m is not None:
            _non_negative("MotionConfig.liftoff_shift_tolerance_m", self.liftoff_shift_tolerance_m)
        if self.liftoff_capture_behind_m is not None:
            _non_negative("MotionConfig.liftoff_capture_behind_m", self.liftoff_capture_behind_m)
        _non_negative("MotionConfig.stance_hysteresis_m", self.stance_hysteresis_m)
        _positive("MotionConfig.late_contact_timeout_s", self.late_contact_timeout_s)
        _non_negative("MotionConfig.min_swing_s", self.min_swing_s)
        if not 0.0 <= self.stance_hip_weight_w0 <= 1.0:
            raise ConfigError(f"stance_hip_weight_w0 must be in [0, 1], got {self.stance_hip_weight_w0}")


@dataclass(frozen=True)
class JacobianTransposeConfig:
    """The paper's controller as printed (controller.py): PID (Eq. 13) with gravity compensation (Eq. 14-15), the
    COM and root virtual control mapped by Jacobian transposes (Eq. 16-18), the IPM ankle torque (Eq. 20)."""

    pid: dict[str, PidGains] = field(default_factory=_table3)
    integral_limit_rad_s: float = 0.2  # anti-windup clamp of ∫e dt per DOF [rad·s]
    # CR-VC, Eq. 16; Table 3 prints two "Kp" columns, the second is read as Kd.
    com_force_kp_npm: float = 50.0  # Table 3, virtual force Kp [N/m]
    com_force_kd_nspm: float = 30.0  # Table 3, virtual force Kd [N·s/m]
    root_torque_kp: float = 1000.0  # Table 3 gives 5000; see docs/decisions.md [N·m/rad]
    root_torque_kd: float = 100.0  # Table 3 gives 1000; see docs/decisions.md [N·m·s/rad]
    # In single stance the stance hip carries the root torque alone and cancels the other pelvis joints'
    # feedback (SIMBICON's torso control, controller.py); off by default: measured no better overall
    # (docs/decisions.md). Off, the root torque is one more implicit term on the stance hips.
    stance_hip_torso: bool = False
    gravity_compensation: bool = True  # Eq. 14-15
    com_virtual_force: bool = True  # Eq. 16-17
    root_virtual_torque: bool = True  # Eq. 16, 18
    ipm_ankle_compensation: bool = True  # Eq. 20

    def __post_init__(self) -> None:
        for n in ("com_force_kp_npm", "com_force_kd_nspm", "root_torque_kp", "root_torque_kd"):
            _non_negative(f"JacobianTransposeConfig.{n}", getattr(self, n))
        _positive("JacobianTransposeConfig.integral_limit_rad_s", self.integral_limit_rad_s)
        for group in ("chest", "neck", "hip", "knee", "ankle", "shoulder", "elbow"):
            if group not in self.pid:
                raise ConfigError(f"JacobianTransposeConfig.pid lacks gains for '{group}'")


OWN_STEP_PUSH_BOUNDS = ("off", "he_stands", "always")  # WholeBodyConfig.own_step_push_bound
RECOVERY_FOOT_TARGET_RATES = ("differenced", "profile")  # WholeBodyConfig.recovery_foot_target_rate


@dataclass(frozen=True)
class WholeBodyConfig:
    """The whole-body controller (whole_body.py): tasks and sole contacts in one QP per control tick."""

    joint_tracking_omega_rad_s: float = 20.0  # posture task: Eq. 13 as q̈* = ω² e + 2 ζ ω ė
    joint_tracking_damping_ratio: float = 1.0
    joint_acceleration_limit_rad_s2: float = 200.0  # the posture task's desired acceleration is saturated here
    joint_tracking_weight: float = 10.0  # weight of M_ii Δq̈_i² against the momentum task's squared newtons
    # The COM force of Eq. 16 per unit mass, horizontally (Eq. 16, first line) and vertically (the pelvis height of
    # Eq. 9). These are the gains of a capture-point (DCM) tracking law with unit gain for this character's
    # pendulum, kp = ω², kd = 2ω with ω = sqrt(g / h) ≈ 3.4 1/s, instead of Table 3's 50 and 30 (docs/decisions.md)
    # [1/s², 1/s].
    momentum_com_kp: float = 12.0
    momentum_com_kd: float = 7.0
    # While a step of the character's own is due to land and the pelvis is above its target, the pelvis height's law
    # with these gains instead: the soft ones left the hip 0.1 m above a target lowered for the landing and the foot
    # above the ground while the body ran past it (docs/decisions.md, "An own step's foot held above its landing").
    # None: the gains above [1/s², 1/s]
    landing_pelvis_gains: tuple[float, float] | None = None
    momentum_root_kp: float = 200.0  # root virtual torque of Eq. 16 about the COM [N·m/rad]
    momentum_root_kd: float = 40.0  # [N·m·s/rad]
    momentum_moment_weight_per_m: float = 2.0  # the moment rows' weight is this squared, the force rows' 1 [1/m]
    # The moment of Eq. 16 less this rate times the whole body's angular momentum about its COM (centroidal momentum
    # damping, L̇* = τ_root - k L): the posture's tracking of his limbs pumps angular momentum into the smaller body
    # that no task takes out. At 5 1/s (`--damp-angular-momentum`), of the looping dances, spins, the spinning kick and
    # the jump, 23 of 40 minutes stand against 16, but over the development suite (seeds 0-7) the walking categories
    # keep within the UHC distance on 57 runs against 65 and the spinning kick falls twice more; at 7 1/s and more the
    # built-in walk goes out of step with him (docs/decisions.md, "The body's angular momentum damped"). 0: off [1/s]
    angular_momentum_damping_1ps: float = 0.0
    contact_velocity_gain: float = 10.0  # a supporting sole's residual velocity is damped at this rate [1/s]
    # A sole's forces as one wrench inside its contact wrench cone (sole_wrench_contact.py: 6 variables and the
    # cone's 32 faces) instead of 16 magnitudes along its corners' friction pyramids (contacts.py).
    sole_wrench_cone: bool = False
    # A planted sole whose lowest corner is within this height of the ground still counts as supporting
    # (contacts.sole_touches); 0 = only a foot pressing the ground does. Off by default, as
    # WorldConfig.friction_anchor, with which it keeps a standing character's feet planted [m].
    sole_contact_gap_m: float = 0.0
    # The hands follow the operator's hands in world space (a task each, off by default) [1/s², 1/s]
    hand_tasks: bool = False
    # A stance foot that has come off the ground (its force planned at zero while the weight shifts off it) is held
    # where it came off, horizontally, as well as pressed down: left free, the QP swung it for momentum and it slid
    # 0.2 m over the ground before a kick (docs/decisions.md, "A kick that strikes: the free swing"). It holds a
    # runner's rear foot back too: 323 of 352 suite runs completed against 337 (runs 33 of 48 against 42), and 324
    # with --free-swing against 336 without it: off, and not part of --free-swing.
    press_holds_foot: bool = False
    # In the character's double stance, a foot off the ground is pressed down whatever its stance weight: with the
    # COM over the other foot its weight is zero, and, neither pressed nor bearing, it rose 0.19 m with the posture
    # until the weight came back to it and neither sole bore any (docs/decisions.md, "A double stance's unweighted
    # foot"). False: only a foot with a stance weight is pressed down.
    press_double_stance_feet: bool = True
    hand_task_kp: float = 100.0
    hand_task_kd: float = 20.0
    hand_task_weight: float = 100.0
    # The swing ankle of a step the character takes on its own (motion/recovery_step.py) follows its target in world
    # space (a task, ReferencePose.recovery_ankle_world): through the joint posture alone it trailed its target by
    # 0.2-0.3 m at mid-swing and landed 0.1 s late, short of the capture point (docs/decisions.md, "Recovery steps
    # that land"; weight 0: off) [1/s², 1/s, -]
    recovery_foot_task_kp: float = 400.0
    recovery_foot_task_kd: float = 40.0
    recovery_foot_task_weight: float = 100.0
    # Once the step's landing is due (its target pressed below the ground, recovery_step.swing_target) and the foot has
    # not touched yet, its task weighs this. Traced on the falls left in the development suite: most end in recovery
    # steps whose foot hovers 3-4 cm above the ground for 0.2-0.5 s past its touchdown, while the body sinks onto the
    # folding swing leg (docs/decisions.md, "A recovery step's landing that is due"). The weight of the press on a
    # stance foot that has not touched yet (whole_body.FOOT_TASK_WEIGHT) [-]
    recovery_foot_landing_weight: float = 1000.0
    # The velocity the foot task's target is followed with (the task's kd term): "profile", the swing profile's own
    # (recovery_step.RecoveryStepper.swing_target, the landing held where it is this tick), or "differenced", the
    # target's change since the last control tick. The landing is re-planned each tick on the capture point, which the
    # swing leg's own reaction moves: differenced, the re-plannings alternated each tick, became target velocities of
    # +-5 m/s and drove the leg, whose foot went up instead of landing (docs/decisions.md, "A due landing's foot that
    # goes up").
    recovery_foot_target_rate: str = "profile"
    # In a step of the character's own, on one sole, the ground's horizontal force along the capture point's
    # divergence from that sole is at most the pendulum's with the centre of pressure at the sole's rear edge along
    # it (control/own_step_push.py): the step's swing is not driven by pushing the body further the way it already
    # diverges (docs/decisions.md, "A character's own steps that push it on"). "off", "he_stands" (in the steps
    # taken while the operator stands: the steps that are to stop the body; traced on a chain of them that ran away
    # in the rest after a clip) or "always" (in every step of its own: the default, as the steps walk on with him).
    own_step_push_bound: str = "always"
    # The joints' no-load speed (control/joint_speed_limit.py): a joint turning faster than this gets no torque along
    # its motion. Human joints peak at about 20-30 rad/s (a kick's knee); the held torques of a control tick spun
    # light links (a lifting stance foot, a hand) to the engine's 100 rad/s within a tick (docs/decisions.md, "The
    # joints' no-load speed"); None: unlimited [rad/s].
    joint_speed_limit_rad_s: float | None = 30.0
    # The posture task's weight on the hip, knee and ankle of each supporting leg, as a share of its weight elsewhere.
    # A supporting leg closes a chain through the ground: its joint angles are where the pelvis is over the foot,
    # which the momentum task (the COM), the pelvis height and the pelvis orientation already ask for. At full weight
    # the leg's posture (the operator's crouch or push-off, retargeted) drove the COM past the feet before jumps
    # (docs/decisions.md, "The supporting legs' posture")
    stance_leg_tracking_share: float = 0.1
    # While the operator stands still (on both feet, his feet and his COM at rest) and the character stands on both
    # soles (its COM below 0.25 m/s, no weight shift of its own for a step to where he stands: ReferencePose.
    # both_stand_still), both soles stay contacts whatever their stance weight (at least the contacts' MIN_WEIGHT) and
    # each is planned to bear at least this share of the body's weight (ramped down with its stance weight below the
    # contacts' RAMP_WEIGHT). A sole his weight leaves all but unloaded otherwise pressed the ground on one control
    # tick and not on the next, left the QP's contacts and came back, and slid; the character then stepped to put it
    # back, again and again (docs/decisions.md, "A sole unloaded where he stands", "The standing soles' load by
    # default"). 0: off [-]
    standing_sole_min_load_share: float = 0.1
    # The pelvis orientation task's weight in single stance, as a share of its weight on two feet. A swing leg driven
    # forward and up (a running stride) turns the pelvis the other way; a pelvis held level at full weight took that
    # acceleration from the swing leg, whose foot then went back instead of forward (docs/decisions.md, "The pelvis
    # in single stance")
    single_stance_pelvis_share: float = 0.3
    # A QP with no feasible point is solved again with the joint torque limits and the hinges' limit horizon opened
    # (the torques are clipped to their limits afterwards, and the engine keeps the joints within theirs); the root's
    # equations of motion and the soles' contact rows stay. A supporting leg stretched to its knee's limit closes a
    # chain whose contact rows then ask for more than the limits allow, and the last iterate of the failed solve,
    # applied as torques, threw the limbs at 30-40 m/s (docs/decisions.md, "A QP with no feasible point")
    relax_limits_when_infeasible: bool = True
    # The pelvis height's law also tracks this share of the target's rise on both feet: force_z = m (kp (z_d - z) +
    # kd (share ż_d - ż)), ż_d the operator's pelvis's upward speed scaled (Eq. 9; ReferencePose.pelvis_vel_z_mps),
    # handed on only for a jump's push (MotionConfig.rise_begun_on_both_feet). 0 (`--no-track-rise`): the regulator
    # alone, which damps every vertical speed: from a crouch before a jump the character rose over 0.7 s where he
    # sprang up in 0.43 s (docs/decisions.md, "A jump's rise", "A jump's push, begun on both feet") [-]
    pelvis_rate_share: float = 0.5
    # A rear sole goes onto its toes (control/toe_contact.py): on two feet, the foot behind the body whose leg is
    # stretched to this share of its length (hip to ankle) or more stands on its toe line, its heel free to rise, as a
    # walker's heel rises before his rear foot lifts; held flat, a straight rear leg pinned the pelvis to its arc and
    # brought it down by 0.1-0.15 m in a long stride (docs/decisions.md, "A rear foot on its toes"). None: the soles
    # stay flat [-]
    toe_off_leg_stretch: float | None = None
    # ... while the operator goes somewhere at least this fast (ReferencePose.his_way_speed_mps): a gait's heel-off,
    # not a stretched leg in a jump's landing or a lunge on the spot [m/s]
    toe_off_min_way_speed_mps: float = 0.3

    def __post_init__(self) -> None:
        for n in ("joint_tracking_omega_rad_s", "joint_tracking_damping_ratio", "momentum_moment_weight_per_m",
                  "joint_acceleration_limit_rad_s2"):
            _positive(f"WholeBodyConfig.{n}", getattr(self, n))
        for n in ("momentum_com_kp", "momentum_com_kd", "momentum_root_kp", "momentum_root_kd",
                  "angular_momentum_damping_1ps", "contact_velocity_gain", "sole_contact_gap_m",
                  "joint_tracking_weight", "hand_task_kp",
                  "hand_task_kd", "hand_task_weight", "stance_leg_tracking_share", "single_stance_pelvis_share",
                  "recovery_foot_task_kp", "recovery_foot_task_kd", "recovery_foot_task_weight",
                  "recovery_foot_landing_weight", "pelvis_rate_share", "toe_off_min_way_speed_mps"):
            _non_negative(f"WholeBodyConfig.{n}", getattr(self, n))
        if self.joint_speed_limit_rad_s is not None:
            _positive("WholeBodyConfig.joint_speed_limit_rad_s", self.joint_speed_limit_rad_s)
        if self.toe_off_leg_stretch is not None:
            _positive("WholeBodyConfig.toe_off_leg_stretch", self.toe_off_leg_stretch)
        if self.landing_pelvis_gains is not None:
            try:
                kp, kd = (float(v) for v in self.landing_pelvis_gains)
            except (TypeError, ValueError):
                raise ConfigError("WholeBodyConfig.landing_pelvis_gains must be two numbers (kp [1/s²], kd [1/s]) or "
                                  f"None, got {self.landing_pelvis_gains!r}") from None
            _non_negative("WholeBodyConfig.landing_pelvis_gains kp", kp)
            _non_negative("WholeBodyConfig.landing_pelvis_gains kd", kd)
            object.__setattr__(self, "landing_pelvis_gains", (kp, kd))
        if self.recovery_foot_target_rate not in RECOVERY_FOOT_TARGET_RATES:
            raise ConfigError(f"WholeBodyConfig.recovery_foot_target_rate must be one of "
                              f"{', '.join(RECOVERY_FOOT_TARGET_RATES)}, got '{self.recovery_foot_target_rate}'")
        if self.own_step_push_bound not in OWN_STEP_PUSH_BOUNDS:
            raise ConfigError(f"WholeBodyConfig.own_step_push_bound must be one of {', '.join(OWN_STEP_PUSH_BOUNDS)}, "
                              f"got '{self.own_step_push_bound}'")


@dataclass(frozen=True)
class ControlConfig:
    """The balance and synchronisation controller (Sec. 6): which method realises it, and what both share."""

    # "whole_body" (whole_body.py: tasks and sole contacts in one QP per tick) or "jacobian_transpose"
    # (controller.py: Eq. 17-18 and Eq. 20 as printed, with the stable PD). See docs/decisions.md.
    balance: str = "whole_body"
    whole_body: WholeBodyConfig = field(default_factory=WholeBodyConfig)
    jacobian_transpose: JacobianTransposeConfig = field(default_factory=JacobianTransposeConfig)
    # Extra scaling of the root torque about the vertical (heading), which the stance hips also carry.
    root_yaw_gain_scale: float = 1.0
    lipm_time_sync: bool = True  # Eq. 21-23
    enforce_bounds: bool = True  # Eq. 24-28
    lipm_force_limit_n: float = 150.0  # clamp of |f_cro| before the bounds check [N]

    def __post_init__(self) -> None:
        _positive("ControlConfig.root_yaw_gain_scale", self.root_yaw_gain_scale)
        _non_negative("ControlConfig.lipm_force_limit_n", self.lipm_force_limit_n)
        if self.balance not in BALANCE_METHODS:
            raise ConfigError(f"ControlConfig.balance must be one of {BALANCE_METHODS}, got {self.balance!r}")


# A recording starts at its own velocities, no faster than this over the ground (OperatorConfig.start_speed_max_mps)
# [m/s]
FOLLOW_PATH_START_SPEED_MAX_MPS = 1.0


START_RAMPS = ("blend", "rate")  # how a looping built-in clip starts after the lead-in (OperatorConfig.start_ramp)


@dataclass(frozen=True)
class OperatorConfig:
    """The built-in operator: a recorded clip played by a human-scale skeleton through a Kinect-like sensor."""

    clip: str = "walk"  # pybullet_data humanoid3d_<clip>.txt
    height_m: float = 1.75
    mass_kg: float = 75.8  # Table 2, human column total
    position_noise_m: float = 0.005  # Kinect-like joint position noise (1 sigma) [m]
    orientation_noise_rad: float = 0.02  # joint orientation noise (1 sigma) [rad]
    timestamp_jitter_s: float = 0.004  # sample-time jitter (1 sigma) [s]
    standing_lead_in_s: float = 1.0  # operator stands in the first frame's pose before the clip plays [s]
    # A looping clip's start after the lead-in (sources/builtin_operator.py): "blend", a neutral stand blended into
    # the clip (his feet slide, and a turning clip turns him the shorter way at once); "rate", his pose the clip's own
    # at the phase where his feet are lowest and the clip's time running at a rate that grows from 0 to 1 (no slide,
    # no turn but the clip's; measured, not the default: docs/decisions.md, "A built-in clip's start at a growing rate")
    start_ramp: str = "blend"  # one of START_RAMPS
    start_ramp_s: float = 1.5  # ... over this time [s]
    # The clip played this many times faster after the lead-in (the operator walks faster: cadence and speed) [-]
    playback_speed: float = 1.0
    # The clip's path bent into a turn at this rate after the lead-in (+: counter-clockwise seen from above;
    # sources/turning_path.py): the built-in walks go straight, people turn. 0: as recorded [rad/s]
    turn_rate_rad_s: float = 0.0
    # A recorded file (BVH, k4a JSON) starts the character in its first frame's pose (motion/initial_state.py)
    # instead of the standing lead-in, and the operator holds the last frame for
    # rest_after_clip_s while the character comes to rest (part of the run).
    start_in_motion: bool = True
    rest_after_clip_s: float = 3.0
    # Started in motion, the character also takes the clip's velocities (DeepMimic's full reference-state
    # initialisation). Off: measured on the shared walks, a character started at the clip's speed falls within 1 s
    # on 5 of 6 (its COM ahead of the reference, which lags the operator by the processing delay), while one
    # started at rest in the clip's pose accelerates behind the reference and walks the clip (docs/decisions.md).
    # On, the 1€ filter and the motion stage's COM rates start from the clip's rates too (no lag of a filter that
    # believes the operator at rest); measured on the walk set, 28 of 56 runs complete against 33-37 started at rest.
    # With the start bounded below (start_speed_max_mps) and the steps that walk on with him, it is the default
    # (docs/decisions.md, "Following his path by default").
    start_with_clip_velocity: bool = True
    # ... at most this fast over the ground: the character's velocities (root and joints) scaled down together so
    # that its root's horizontal speed is no more (None: the clip's as they are). A body started faster than its steps
    # can catch falls forward through them (docs/decisions.md) [m/s]
    start_speed_max_mps: float | None = FOLLOW_PATH_START_SPEED_MAX_MPS
    # Every source's frames as their mirror image, his right side driving the character's left (sources/mirror.py):
    # for a person facing the character on a screen, who expects it to move like his reflection.
    mirror: bool = False

    def __post_init__(self) -> None:
        _positive("OperatorConfig.height_m", self.height_m)
        _positive("OperatorConfig.mass_kg", self.mass_kg)
        _non_negative("OperatorConfig.position_noise_m", self.position_noise_m)
        if self.start_speed_max_mps is not None:
            _non_negative("OperatorConfig.start_speed_max_mps", self.start_speed_max_mps)
        _non_negative("OperatorConfig.orientation_noise_rad", self.orientation_noise_rad)
        _non_negative("OperatorConfig.timestamp_jitter_s", self.timestamp_jitter_s)
        _non_negative("OperatorConfig.standing_lead_in_s", self.standing_lead_in_s)
        _non_negative("OperatorConfig.start_ramp_s", self.start_ramp_s)
        if self.start_ramp not in START_RAMPS:
            raise ConfigError(f"OperatorConfig.start_ramp {self.start_ramp!r}: expected one of "
                              f"{', '.join(START_RAMPS)}")
        _positive("OperatorConfig.playback_speed", self.playback_speed)
        if not math.isfinite(self.turn_rate_rad_s):
            raise ConfigError(f"OperatorConfig.turn_rate_rad_s must be finite, got {self.turn_rate_rad_s}")
        _non_negative("OperatorConfig.rest_after_clip_s", self.rest_after_clip_s)


@dataclass(frozen=True)
class SessionConfig:
    clocks: ClockConfig = field(default_factory=ClockConfig)
    world: WorldConfig = field(default_factory=WorldConfig)
    filters: FilterConfig = field(default_factory=FilterConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    control: ControlConfig = field(default_factory=ControlConfig)
    operator: OperatorConfig = field(default_factory=OperatorConfig)
    duration_s: float = 12.0
    seed: int = 0
    realtime: bool = False  # paced to the wall clock (interactive) or as fast as possible (offline)
    gui: bool = False
    # A live stream silent for longer than this ends the run (its outputs written); shorter silences are held [s]
    stream_timeout_s: float = 5.0
    # The motion stage on the last control tick's state (7.5 ms old) with this tick's operator sample, computed a tick
    # ahead in a second process when the operator side is prefetched (motion_ahead.py): the pipeline about 1.1 times
    # as fast, and another simulation; off, the motion stage reads this tick's state in this process
    # (docs/decisions.md, "The motion stage a tick ahead")
    motion_ahead: bool = False

    def __post_init__(self) -> None:
        _positive("SessionConfig.duration_s", self.duration_s)
        _positive("SessionConfig.stream_timeout_s", self.stream_timeout_s)

    def replace(self, **changes) -> SessionConfig:
        return dataclasses.replace(self, **changes)


# The settings of the character that stays about where it started, its steps planned to stop the body and its
# targets anchored on its own feet, trailing an operator who walks off (the defaults before "Following his path by
# default", docs/decisions.md): `--in-place`. It falls a little less often and keeps his gait's timing a little
# closer; it goes about a third of his way.
IN_PLACE_MOTION: dict[str, Any] = {
    "double_stance_keeps_momentum_m": None,  # a gait's double stance brakes the body ...
    "capture_bound_in_his_gait": True,  # ... to the capture bound of its soles
    "capture_bound_before_his_landing": True,
    "gait_capture_step_s": None,
    "reference_follows_operator_s": 0.0,  # the targets anchored on its feet (Eq. 10)
    "reference_follows_standing_s": None,  # (moot with the above; the former default had none)
    "reference_lead_max_m": None,
    "path_feedback_share": 0.0,  # no landing moved towards his path
    "recovery_walk_on_m": None,  # its own steps stop the body
    "recovery_walk_on_his_way": False,
    "gait_min_way_speed_mps": None,
    "path_target_share": 0.0,
    "rest_step_min_m": None,  # it stays where it stopped
}
IN_PLACE_WHOLE_BODY: dict[str, Any] = {
    "own_step_push_bound": "he_stands",
}
IN_PLACE_OPERATOR: dict[str, Any] = {
    "start_with_clip_velocity": False,  # a recording started at rest in its first pose
    "start_speed_max_mps": None,
}


def with_settings(cfg: SessionConfig, motion: dict[str, Any] | None = None, whole_body: dict[str, Any] | None = None,
                  operator: dict[str, Any] | None = None) -> SessionConfig:
    """``cfg`` with these settings of its MotionConfig, WholeBodyConfig and OperatorConfig (a set of them that a
    command-line option names)."""
    control = cfg.control
    if whole_body:
        control = dataclasses.replace(control, whole_body=dataclasses.replace(control.whole_body, **whole_body))
    return cfg.replace(motion=dataclasses.replace(cfg.motion, **(motion or {})), control=control,
                       operator=dataclasses.replace(cfg.operator, **(operator or {})))


def in_place(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with IN_PLACE_MOTION, IN_PLACE_WHOLE_BODY and IN_PLACE_OPERATOR."""
    return with_settings(cfg, IN_PLACE_MOTION, IN_PLACE_WHOLE_BODY, IN_PLACE_OPERATOR)


def _defaults(cls: type, names: dict[str, Any]) -> dict[str, Any]:
    """The field defaults of the dataclass ``cls`` for the keys of ``names``."""
    fields = {f.name: f.default for f in dataclasses.fields(cls)}
    return {name: fields[name] for name in names}


# Following the operator's path over the ground closer still, at a cost in falls and in his gait's timing: the
# defaults of every setting `--in-place` changes (so that it gives the same settings over any base), and besides them
# the targets pulled onto his path at every speed of his, not only below the character's gait's top speed
# (docs/decisions.md, "Following the operator's path by the landing", "Targets on his path", "The targets on his path
# below the gait's top speed"): `--follow-path`.
FOLLOW_PATH_MOTION: dict[str, Any] = _defaults(MotionConfig, IN_PLACE_MOTION) | {
    "path_target_share": 1.0,  # the targets pulled to his path, at most path_target_max_m (0.3 m) ahead,
    "path_target_fade_from_mps": None,  # ... at every speed of his
    "path_target_step_hold_s": None,  # ... whether he steps or not
    "path_target_along_cos": None,  # ... and whether he goes along his way or not
    "landing_reach_ground_gap_m": 0.003,  # a foot lying on the ground, pressing or not, lowers no pelvis target
}
# ... in the whole-body controller: the push of the character's own steps bounded while he walks too
FOLLOW_PATH_WHOLE_BODY: dict[str, Any] = _defaults(WholeBodyConfig, IN_PLACE_WHOLE_BODY)


# The opt-ins that let a kick strike (docs/decisions.md, "A kick that strikes: the free swing"): `--free-swing`.
FREE_SWING_MOTION: dict[str, Any] = {
    "free_swing": True,  # a swing neither he nor the character needs to land follows his foot
    "liftoff_shift_outward_m": 0.01,  # and is not lifted with the weight already beyond the stance ankle
}


# A swing held for a late contact taken over by the balance where his landing would not hold the capture point
# (docs/decisions.md, "A late contact that the balance takes over"): `--late-contact-steps`.
LATE_CONTACT_STEPS_MOTION: dict[str, Any] = {
    "recovery_in_late_contact": True,
}


# His skeleton's pelvis joint as his pelvis and the pelvis target at his, scaled: the settings before 2026-12-06
# (docs/decisions.md, "His pelvis at his hip joints", "His pelvis at his hip joints by default"): `--pelvis-joint`.
PELVIS_JOINT_MOTION: dict[str, Any] = {
    "pelvis_from_hip_joints": False,
    "pelvis_height_offset_m": 0.0,
}


def pelvis_joint(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with PELVIS_JOINT_MOTION."""
    return with_settings(cfg, motion=PELVIS_JOINT_MOTION)


def free_swing(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with FREE_SWING_MOTION."""
    return with_settings(cfg, motion=FREE_SWING_MOTION)


def late_contact_steps(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with LATE_CONTACT_STEPS_MOTION."""
    return with_settings(cfg, motion=LATE_CONTACT_STEPS_MOTION)


# The pelvis height's law without the operator's rise, the regulator alone (docs/decisions.md, "A jump's rise"):
# `--no-track-rise`.
NO_TRACK_RISE_WHOLE_BODY: dict[str, Any] = {
    "pelvis_rate_share": 0.0,  # every vertical speed damped, his jump's push included
}


def no_track_rise(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with NO_TRACK_RISE_WHOLE_BODY."""
    return with_settings(cfg, whole_body=NO_TRACK_RISE_WHOLE_BODY)


# The whole body's angular momentum about its COM damped at 5 1/s (docs/decisions.md, "The body's angular momentum
# damped"): `--damp-angular-momentum`.
DAMP_ANGULAR_MOMENTUM_WHOLE_BODY: dict[str, Any] = {
    "angular_momentum_damping_1ps": 5.0,
}


def damp_angular_momentum(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with DAMP_ANGULAR_MOMENTUM_WHOLE_BODY."""
    return with_settings(cfg, whole_body=DAMP_ANGULAR_MOMENTUM_WHOLE_BODY)


# ... and for a recording: started at its own velocities, no faster than FOLLOW_PATH_START_SPEED_MAX_MPS
FOLLOW_PATH_OPERATOR: dict[str, Any] = _defaults(OperatorConfig, IN_PLACE_OPERATOR)


def follow_path(cfg: SessionConfig) -> SessionConfig:
    """``cfg`` with FOLLOW_PATH_MOTION, FOLLOW_PATH_WHOLE_BODY and FOLLOW_PATH_OPERATOR (a recording's start at its
    own velocities, at most FOLLOW_PATH_START_SPEED_MAX_MPS)."""
    return with_settings(cfg, FOLLOW_PATH_MOTION, FOLLOW_PATH_WHOLE_BODY, FOLLOW_PATH_OPERATOR)


def pid_group(joint_name: str) -> str:
    """Table 3 row of a joint ('right_hip' -> 'hip')."""
    return joint_name.split("_")[-1]

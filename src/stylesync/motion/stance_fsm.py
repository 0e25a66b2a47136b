"""Motion states and state transitions (Sec. 5.1, Fig. 6): LS, RS and DS.

Operator side: DS while the height difference of the two ankles is within a threshold (with hysteresis);
otherwise the lower foot is the stance foot. Optionally (MotionConfig.his_landing_max_speed_mps) a single stance
ends only once the swing foot has also stopped travelling over the ground. Character side: follows the operator,
with the contact-driven transitions of Sec. 5.1:
* early contact: the swing foot touches down before the operator's state changes -> DS at once (held until the
  operator's state changes, so that it does not flip back);
* late contact: the operator is back in DS but the character's swing foot is still in the air -> the reference
  is held (``hold_reference``) until the foot touches down (or a timeout passes);
* recovery step (recovery_step.py): the operator stands, the character lifts a foot on its own
  (:meth:`CharacterStanceFsm.begin_recovery_step`); the step ends when the foot touches down after the minimum
  swing time (or a timeout passes), whatever the operator does meanwhile; if he lifted the same foot, his step
  counts as taken (as an early contact).
"""

from __future__ import annotations

from enum import Enum

from stylesync.model.character import OTHER_SIDE


class Stance(Enum):
    LS = "LS"  # left stance (right foot swinging)
    RS = "RS"  # right stance
    DS = "DS"  # double stance


def swing_side(s: Stance) -> str | None:
    return "right" if s is Stance.LS else ("left" if s is Stance.RS else None)


def stance_weights(s: Stance, ds_left_share: float) -> dict[str, float]:
    if s is Stance.LS:
        return {"left": 1.0, "right": 0.0}
    if s is Stance.RS:
        return {"left": 0.0, "right": 1.0}
    w = min(max(ds_left_share, 0.0), 1.0)
    return {"left": w, "right": 1.0 - w}


class OperatorStanceFsm:
    def __init__(self, threshold_m: float, hysteresis_m: float):
        self.threshold_m = threshold_m
        self.hysteresis_m = hysteresis_m
        self.state = Stance.DS

    def update(self, ankle_left_z: float, ankle_right_z: float, swing_moving: bool = False) -> Stance:
        """``swing_moving``: the swing foot still travels over the ground (a single stance does not end then)."""
        diff = ankle_left_z - ankle_right_z  # > 0: left foot higher
        if self.state is Stance.DS:
            leave = self.threshold_m + self.hysteresis_m
            if diff > leave:
                self.state = Stance.RS
            elif diff < -leave:
                self.state = Stance.LS
        else:
            if abs(diff) < self.threshold_m - self.hysteresis_m:
                if not swing_moving:
                    self.state = Stance.DS
            elif diff > self.threshold_m + self.hysteresis_m:
                self.state = Stance.RS
            elif diff < -(self.threshold_m + self.hysteresis_m):
                self.state = Stance.LS
        return self.state


class CharacterStanceFsm:
    def __init__(self, late_contact_timeout_s: float, min_swing_s: float, lift_needs_other_down: bool = False):
        self.timeout_s = late_contact_timeout_s
        self.min_swing_s = min_swing_s
        # A lift-off from double stance waits, with no time limit, while the foot the operator lifts is on the
        # ground and the other is not (MotionConfig.liftoff_needs_other_foot_down)
        self.lift_needs_other_down = lift_needs_other_down
        self.state = Stance.DS
        self.hold_reference = False
        self._swing_start_s = 0.0
        self._hold_start_s = 0.0
        self._holding = False
        self._early_latched_for: Stance | None = None
        self.recovery_step = False  # the current single stance is the character's own recovery step
        self._recovery_timeout_s = 0.0
        self._recovery_start_s = 0.0
        self.waiting_to_lift = False  # the operator has lifted a foot; the character shifts its weight first
        self._lift_wait_from_s: float | None = None

    @property
    def step_counted(self) -> bool:
        """In double stance while the operator is on one foot, his step counted as taken (an early contact, or a
        recovery step that landed while he lifted the same foot): the character waits for his next change."""
        return self.state is Stance.DS and self._early_latched_for is not None

    def begin_recovery_step(self, swing: str, time_s: float, timeout_s: float) -> Stance:
        """From double stance, lift ``swing`` on the character's own decision; the step ends at its contact, or
        after ``timeout_s``."""
        self._early_latched_for = None
        self._enter(Stance.RS if swing == "left" else Stance.LS, time_s)
        self.recovery_step, self._recovery_timeout_s = True, timeout_s
        self._recovery_start_s = time_s
        return self.state

    def take_over_swing(self, time_s: float, timeout_s: float) -> None:
        """The current swing (the operator's step) becomes the character's own recovery step from ``time_s``: it
        ends at its contact, or ``timeout_s`` later, whatever the operator does meanwhile."""
        assert swing_side(self.state) is not None
        self._early_latched_for = None
        self._holding = self.hold_reference = False
        self.recovery_step, self._recovery_timeout_s = True, timeout_s
        self._recovery_start_s = time_s

    def update(self, op: Stance, contact: dict[str, bool], time_s: float,
               can_lift: dict[str, bool] | None = None, lift_wait_s: float = 0.0) -> Stance:
        """The character's stance this tick. ``can_lift``: per foot, whether the character's weight is over the
        other foot; a lift-off from double stance the operator makes with a foot that cannot lift waits (the
        weight shifts meanwhile) until it can, at most ``lift_wait_s``."""
        self.hold_reference = False
        self.waiting_to_lift = False
        if self.recovery_step:
            # The character's own step goes on until its foot lands (or the timeout), whatever the operator does
            # meanwhile: the balance decides where and when it lands.
            sw = swing_side(self.state)
            assert sw is not None
            landed = contact[sw] and time_s - self._swing_start_s >= self.min_swing_s
            if not landed and time_s - self._recovery_start_s < self._recovery_timeout_s:
                return self.state
            self.recovery_step = False
            if op is self.state:  # he lifted the same foot meanwhile: his step counts as taken (early contact)
                self._early_latched_for = op
                self._enter(Stance.DS, time_s)
            else:
                self._enter(op, time_s)
            return self.state
        if self._early_latched_for is not None:
            if op is self._early_latched_for:
                return self.state  # early contact: stay in DS until the operator's state changes
            self._early_latched_for = None
        sw = swing_side(self.state)
        if self.state is op:
            self._lift_wait_from_s = None
            # Early contact: swing foot down before the operator's transition.
            if sw is not None and contact[sw] and time_s - self._swing_start_s >= self.min_swing_s:
                self._early_latched_for = op
                self.state = Stance.DS
            return self.state
        if op is Stance.DS or (sw is not None and swing_side(op) != sw):
            # The character's swing foot must land first (late contact holds the reference).
            if sw is None or contact[sw]:
                self._enter(op, time_s)
            else:
                if not self._holding:
                    self._holding, self._hold_start_s = True, time_s
                if time_s - self._hold_start_s >= self.timeout_s:
                    self._enter(op, time_s)
                else:
                    self.hold_reference = True
            return self.state
        sw_op = swing_side(op)
        if (self.lift_needs_other_down and self.state is Stance.DS and sw_op is not None and contact[sw_op]
                and not contact[OTHER_SIDE[sw_op]]):
            # The foot he lifts is the character's only one on the ground: lifted, it would stand on a foot in the air.
            self.waiting_to_lift = True
            return self.state
        if self.state is Stance.DS and sw_op is not None and can_lift is not None and not can_lift[sw_op]:
            # Lift-off from DS is the operator's decision, but the weight has to be over the stance foot first.
            if self._lift_wait_from_s is None:
                self._lift_wait_from_s = time_s
            if time_s - self._lift_wait_from_s < lift_wait_s:
                self.waiting_to_lift = True
                return self.state
        self._lift_wait_from_s = None
        self._enter(op, time_s)  # lift-off from DS is the operator's decision: follow at once
        return self.state

    def _enter(self, s: Stance, time_s: float) -> None:
        self._holding = False
        if s is not Stance.DS and self.state is not s:
            self._swing_start_s = time_s
        self.state = s

"""Recovery steps on the capture point (motion/recovery_step.py), the support polygon (model/sole.py) and the
stance FSM's own steps."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import TRACED_BEFORE_LANDING_WEIGHT, TRACED_BEFORE_PRESS, TRACED_DIFFERENCED, suite_run

from stylesync import rotations as rot
from stylesync.config import ControlConfig, MotionConfig, OperatorConfig, SessionConfig, WholeBodyConfig
from stylesync.control.whole_body import recovery_landing_due
from stylesync.errors import ConfigError
from stylesync.model.character import ANKLE_HEIGHT_M, FOOT_CENTER_AHEAD_OF_ANKLE_M, FOOT_LENGTH_M, LINK_NAMES
from stylesync.model.sole import convex_hull_xy, outside_distance_m, sole_corners_world, sole_outside_m
from stylesync.motion.pose_optimization import CHAR_LEG_LENGTH_M, LANDING_REACH
from stylesync.motion.recovery_step import (
    MIN_FOOT_SEPARATION_M,
    RecoveryStep,
    RecoveryStepper,
    WalkOn,
    beyond_sole_towards_m,
    capture_point,
    not_across,
    operator_stands,
    out_of_reach_after_wait,
    soles_on_ground,
    stands_on,
    support_outside_along,
    support_outside_m,
)
from stylesync.motion.stance_fsm import CharacterStanceFsm, Stance

G = 9.8
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
ANKLES = {"left": np.array([0.0, 0.1, ANKLE_HEIGHT_M]), "right": np.array([0.0, -0.1, ANKLE_HEIGHT_M])}
QUATS = {"left": IDENTITY, "right": IDENTITY}
MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"


def traced_motion(**kwargs) -> MotionConfig:
    """The scenarios of this module were traced with the swing aimed at the operator's swing foot's present offset
    from his capture point (MotionConfig.swing_landing "his_foot_now", the swing as it was then), and with the reach
    rule predicting for now once his usual swing time is past (``recovery_overdue_swing_horizon`` off), and a
    recovery step's landing short of the crossover clearance always moved outwards, in the heading frame
    (``recovery_cross_nearest`` and ``recovery_cross_stance_frame`` off), a foot in the air stepping whatever
    its distance to the capture point (``recovery_landing_foot_waits`` off), and Eq. 10's fraction by side after a
    step of the character's own (``fraction_needs_feet_in_his_order`` off): their motion configurations start from
    it. They were traced before a recovery step's timing adapted to its reach (``recovery_swing_min_s`` None), and
    before a lift-off waited for the other foot to be down (``liftoff_needs_other_foot_down`` off), and while a
    lift-off onto a sole the capture point has passed waited only the weight shift's time (``liftoff_behind_waits``
    off), and before the pelvis target came down as his swing went (``swing_landing_within_reach`` off), and before
    his raised rear foot was read through a band (``rear_foot_support_hysteresis_m`` 0)."""
    return MotionConfig(**{"swing_landing": "his_foot_now", "recovery_overdue_swing_horizon": False,
                           "rear_foot_support_hysteresis_m": 0.0,
                           "recovery_swing_min_s": None, "liftoff_needs_other_foot_down": False,
                           "liftoff_behind_waits": False, "swing_landing_within_reach": False,
                           "recovery_cross_nearest": False, "recovery_cross_stance_frame": False,
                           "recovery_landing_foot_waits": False, "fraction_needs_feet_in_his_order": False,
                           **kwargs})


def test_support_polygon_distance_is_signed_and_finds_the_nearest_point():
    square = convex_hull_xy(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], dtype=float))
    assert len(square) == 4
    d, p = outside_distance_m(np.array([0.5, 0.25]), square)
    assert d == pytest.approx(-0.25) and np.allclose(p, [0.5, 0.25])
    d, p = outside_distance_m(np.array([2.0, 0.5]), square)
    assert d == pytest.approx(1.0) and np.allclose(p, [1.0, 0.5])
    d, p = outside_distance_m(np.array([2.0, 2.0]), square)
    assert d == pytest.approx(np.sqrt(2.0)) and np.allclose(p, [1.0, 1.0])


def test_a_capture_point_counts_as_behind_a_sole_only_outside_it_on_the_other_foots_side():
    front, rear = np.array([0.3, 0.1, ANKLE_HEIGHT_M]), np.array([0.0, -0.1, ANKLE_HEIGHT_M])
    heel_x = front[0] + FOOT_CENTER_AHEAD_OF_ANKLE_M - FOOT_LENGTH_M / 2
    # 6 cm behind the front heel, in line with it: outside towards the rear foot.
    assert beyond_sole_towards_m(np.array([heel_x - 0.06, 0.1]), front, IDENTITY, rear) == pytest.approx(0.06)
    # Over the front sole, or outside it beyond its toe (away from the rear foot): not behind.
    assert beyond_sole_towards_m(np.array([front[0], 0.1]), front, IDENTITY, rear) == 0.0
    assert beyond_sole_towards_m(np.array([front[0] + 0.3, 0.1]), front, IDENTITY, rear) == 0.0
    # Seen from the rear foot, the same point ahead of it is on the front foot's side.
    toe_x = rear[0] + FOOT_CENTER_AHEAD_OF_ANKLE_M + FOOT_LENGTH_M / 2
    assert beyond_sole_towards_m(np.array([toe_x + 0.05, -0.1]), rear, IDENTITY, front) == pytest.approx(0.05)


def test_sole_corners_span_the_foot_ahead_of_the_ankle():
    corners = sole_corners_world(ANKLES["left"], IDENTITY)
    assert np.allclose(corners[:, 2], 0.0)
    assert corners[:, 0].max() - corners[:, 0].min() == pytest.approx(FOOT_LENGTH_M)
    assert corners[:, 0].mean() == pytest.approx(FOOT_CENTER_AHEAD_OF_ANKLE_M)


def test_no_step_while_the_capture_point_is_over_the_feet():
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    com = np.array([0.04, 0.0, 0.8])
    assert stepper.trigger(1.0, com, np.zeros(3), ANKLES, QUATS, ["left", "right"]) is None
    # Moving forward slowly: the capture point stays within the soles' toes.
    assert stepper.trigger(1.0, com, np.array([0.2, 0.0, 0.0]), ANKLES, QUATS, ["left", "right"]) is None


def test_a_capture_point_beyond_the_left_foot_lifts_the_right_foot_and_lands_it_beyond_the_capture_point():
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    com, vel = np.array([0.1, 0.03, 0.8]), np.array([0.45, 0.05, 0.0])  # forward and a little to the left
    xi, omega = capture_point(com, vel, G)
    assert omega == pytest.approx(np.sqrt(G / 0.8))
    step = stepper.trigger(1.0, com, vel, ANKLES, QUATS, ["left", "right"])
    assert step is not None and step.side == "right" and stepper.count == 1
    # Planned for "now": the swing sole's trailing edge is where the capture point will be after the swing.
    landing, xi_land = stepper.capture_landing(0.3, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right")
    assert xi_land[0] > xi[0]  # it keeps diverging over the stance sole
    assert landing[0] > ANKLES["right"][0] + 0.1  # the right foot goes forward
    # Well ahead of the left foot (a crossover step's clearance), it may land nearer the left foot's line than
    # MIN_FOOT_SEPARATION_M: the capture point is 6 cm inwards of the left ankle, and so is the landing.
    assert landing[0] > ANKLES["left"][0] + stepper.cfg.recovery_cross_clear_m
    assert ANKLES["left"][1] - MIN_FOOT_SEPARATION_M < landing[1] < ANKLES["left"][1]
    never_across = RecoveryStepper(traced_motion(recovery_cross_clear_m=None), CHAR_LEG_LENGTH_M, G)
    landing_old, _ = never_across.capture_landing(0.3, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right")
    assert landing_old[1] == pytest.approx(ANKLES["left"][1] - MIN_FOOT_SEPARATION_M)  # kept outwards
    reach_m = stepper.cfg.recovery_step_reach_share * CHAR_LEG_LENGTH_M
    assert np.linalg.norm(landing[:2] - ANKLES["left"][:2]) <= reach_m + 0.11
    assert stands_on(xi_land, ANKLES["left"], IDENTITY, landing, np.eye(3))
    # The swing trajectory: rises mid-swing, then is aimed below the ground until it touches.
    mid = stepper.swing_target(1.1, com, vel, ANKLES["left"], IDENTITY, np.eye(3))
    assert mid[2] > ANKLE_HEIGHT_M + 0.03
    late = stepper.swing_target(1.4, com, vel, ANKLES["left"], IDENTITY, np.eye(3))
    assert late[2] < ANKLE_HEIGHT_M and np.allclose(late[:2], step.landing_world[:2])
    stepper.end(1.4)
    assert stepper.step is None
    # Another only after the minimum double stance.
    wait_s = stepper.cfg.recovery_min_stance_s
    assert stepper.trigger(1.4 + 0.5 * wait_s, com, vel, ANKLES, QUATS, ["left", "right"]) is None
    assert stepper.trigger(1.4 + 1.5 * wait_s, com, vel, ANKLES, QUATS, ["left", "right"]) is not None


def test_a_step_that_walks_on_lands_behind_the_capture_point():
    """MotionConfig.recovery_walk_on_m: the ankle that far behind the capture point at the landing, along its
    divergence from the stance sole, where a step that stops the body puts the sole's trailing edge on it."""
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    com, vel = np.array([0.1, 0.1, 0.8]), np.array([0.6, 0.0, 0.0])  # walking forwards over the left foot
    stop, xi_land = stepper.capture_landing(0.2, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right")
    walk, xi_walk = stepper.capture_landing(0.2, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right",
                                            WalkOn(0.1))
    assert xi_walk == pytest.approx(xi_land)
    assert walk[0] == pytest.approx(xi_land[0] - 0.1, abs=1e-9)  # the ankle 0.1 m behind the capture point
    assert stop[0] > xi_land[0]  # the stopping step's ankle beyond it (the sole's trailing edge on it)
    assert walk[1] == pytest.approx(stop[1])  # sideways, the same clearance from the stance foot


def test_a_step_that_walks_on_his_way_walks_on_only_along_it():
    """MotionConfig.recovery_walk_on_his_way: the capture point lands ahead of the ankle only along the operator's way
    over the ground, by the share of its divergence that goes that way; a divergence across his way is caught on the
    ankle, where walking on along the divergence carries a sideways drift into the next step."""
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    way = np.array([1.0, 0.0, 0.0])
    # Diverging forwards and to the right (45°) over the left foot, the right foot to land.
    com, vel = np.array([0.1, 0.0, 0.8]), np.array([0.5, -0.5, 0.0])
    own, xi_land = stepper.capture_landing(0.2, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right",
                                           WalkOn(0.1))
    his, xi_his = stepper.capture_landing(0.2, com, vel, ANKLES["left"], IDENTITY, np.eye(3), "right",
                                          WalkOn(0.1, way))
    assert xi_his == pytest.approx(xi_land)
    u = (xi_land - own[:2]) / 0.1  # along the divergence from the stance sole, sideways too
    assert np.linalg.norm(u) == pytest.approx(1.0) and u[0] > 0.3 and u[1] < -0.3
    assert his[0] == pytest.approx(xi_land[0] - 0.1 * u[0], abs=1e-9)  # along his way: its share of the divergence
    assert his[1] == pytest.approx(xi_land[1], abs=1e-9)  # across it: the capture point on the ankle
    # Diverging against his way (thrown back): no walk-on at all.
    back = WalkOn(0.1, -way)
    assert back.ahead_world(np.array([1.0, 0.0, 0.0])) == pytest.approx(np.zeros(3))
    assert WalkOn(0.1, way).ahead_world(np.array([0.0, 1.0, 0.0])) == pytest.approx(np.zeros(3))


def test_a_foot_in_the_air_that_a_step_would_take_back_from_the_capture_point_is_left_to_land():
    # A stride (CMU-dev 07_01 started at its speed, traced): the left foot 0.7 m ahead of the right, just landed and
    # bounced (not on the ground), the body moving forward over it at 1.3 m/s. Its step, within reach of the right
    # sole far behind, would land it further from the capture point than it is: it is left to land.
    stepper = RecoveryStepper(traced_motion(recovery_landing_foot_waits=True), CHAR_LEG_LENGTH_M, G)
    ankles = {"left": np.array([0.7, 0.1, ANKLE_HEIGHT_M + 0.03]), "right": np.array([0.0, -0.1, ANKLE_HEIGHT_M])}
    com, vel = np.array([0.45, 0.0, 0.8]), np.array([1.3, 0.0, 0.0])
    landing, xi_land = stepper.capture_landing(stepper.cfg.recovery_swing_s, com, vel, ankles["right"], IDENTITY,
                                               np.eye(3), "left")
    assert landing[0] < ankles["left"][0]  # within reach of the right sole: back from where the foot is
    assert stepper.trigger(1.0, com, vel, ankles, QUATS, ["right"], np.eye(3)) is None and stepper.count == 0
    free = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    assert free.trigger(1.0, com, vel, ankles, QUATS, ["right"], np.eye(3)).side == "left"  # as it was traced
    # A foot in the air short of a capture point that runs away behind the body (CMU-dev 03_01, seed 5): its step,
    # beyond the capture point, is better than landing it where it is, and it steps.
    behind = {"left": np.array([-0.35, 0.1, ANKLE_HEIGHT_M + 0.03]), "right": ankles["right"]}
    step = stepper.trigger(1.0, np.array([-0.1, 0.0, 0.8]), np.array([-0.8, 0.0, 0.0]), behind, QUATS, ["right"],
                           np.eye(3))
    assert step is not None and step.side == "left"


def test_a_crossover_landing_needs_its_clearance_ahead_or_behind():
    """Heading frame x forward, y left; the left foot stands at the origin and the right foot swings. Across the
    left foot (y > -MIN_FOOT_SEPARATION_M) a landing stays only if it is at least the clearance ahead or behind;
    beside the stance foot it is moved outwards, and with no clearance (None) always."""
    stance = np.array([0.0, 0.0, ANKLE_HEIGHT_M])
    across_ahead, across_beside = np.array([0.3, 0.2, ANKLE_HEIGHT_M]), np.array([0.05, 0.2, ANKLE_HEIGHT_M])
    np.testing.assert_allclose(not_across(across_ahead, stance, np.eye(3), "right", 0.15), across_ahead)
    behind = np.array([-0.2, 0.1, ANKLE_HEIGHT_M])
    np.testing.assert_allclose(not_across(behind, stance, np.eye(3), "right", 0.15), behind)
    moved = not_across(across_beside, stance, np.eye(3), "right", 0.15)
    np.testing.assert_allclose(moved, [0.05, -MIN_FOOT_SEPARATION_M, ANKLE_HEIGHT_M])
    np.testing.assert_allclose(not_across(across_ahead, stance, np.eye(3), "right", None),
                               [0.3, -MIN_FOOT_SEPARATION_M, ANKLE_HEIGHT_M])
    # the left foot swinging over a right stance: mirrored
    np.testing.assert_allclose(not_across(-across_beside * [1, 1, -1], stance, np.eye(3), "left", 0.15)[1],
                               MIN_FOOT_SEPARATION_M)


def test_a_landing_just_short_of_the_crossover_clearance_goes_to_the_nearer_place_off_the_stance_foot():
    """The right foot swings over a left stance foot at the origin (heading frame x forward, y left). A landing 12 cm
    ahead and 25 cm across (a capture point ahead on the stance foot's far side) was moved 35 cm outwards, to the
    other side of the stance foot; with ``nearest`` it goes 3 cm forward, to the clearance. Just across beside the
    stance ankle, outwards is the nearer and is kept; behind, the clearance is behind."""
    stance, h = np.array([0.0, 0.0, ANKLE_HEIGHT_M]), ANKLE_HEIGHT_M
    short = np.array([0.12, 0.25, h])
    np.testing.assert_allclose(not_across(short, stance, np.eye(3), "right", 0.15), [0.12, -MIN_FOOT_SEPARATION_M, h])
    np.testing.assert_allclose(not_across(short, stance, np.eye(3), "right", 0.15, nearest=True), [0.15, 0.25, h])
    np.testing.assert_allclose(not_across(short * [-1, 1, 1], stance, np.eye(3), "right", 0.15, nearest=True),
                               [-0.15, 0.25, h])
    beside = np.array([0.01, -0.05, h])  # 5 cm from MIN_FOOT_SEPARATION_M, 14 cm from the clearance
    np.testing.assert_allclose(not_across(beside, stance, np.eye(3), "right", 0.15, nearest=True),
                               [0.01, -MIN_FOOT_SEPARATION_M, h])
    np.testing.assert_allclose(not_across(short, stance, np.eye(3), "right", None, nearest=True),
                               [0.12, -MIN_FOOT_SEPARATION_M, h])  # never across: always outwards
    # In a turned heading frame the same, turned.
    R = rot.matrix_from_quat(rot.quat_from_yaw(0.7))
    turned = not_across(stance + R @ (short - stance), stance, R, "right", 0.15, nearest=True)
    np.testing.assert_allclose(R.T @ (turned - stance), [0.15, 0.25, 0.0], atol=1e-12)


def test_recovery_steps_can_be_switched_off():
    stepper = RecoveryStepper(traced_motion(recovery_steps=False), CHAR_LEG_LENGTH_M, G)
    assert stepper.trigger(1.0, np.array([0.3, 0.0, 0.8]), np.array([1.0, 0.0, 0.0]), ANKLES, QUATS,
                           ["left", "right"]) is None


def test_an_operator_mid_stride_at_rest_stands_and_a_walking_one_does_not():
    ankles = {"left": np.array([-0.3, 0.1, 0.08]), "right": np.array([0.3, -0.1, 0.08])}
    yaw = {"left": 0.0, "right": 0.0}
    assert operator_stands(np.array([0.0, 0.0, 0.9]), ankles, yaw, 0.9)
    assert not operator_stands(np.array([0.7, 0.0, 0.9]), ankles, yaw, 0.9)


def test_the_fsm_keeps_a_recovery_step_until_its_foot_lands():
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    both = {"left": True, "right": True}
    assert fsm.update(Stance.DS, both, 0.0) is Stance.DS
    assert fsm.begin_recovery_step("right", 0.1, timeout_s=0.7) is Stance.LS
    up = {"left": True, "right": False}
    assert fsm.update(Stance.DS, up, 0.2) is Stance.LS and fsm.recovery_step and not fsm.hold_reference
    # The operator lifts the same foot meanwhile: the step goes on, and once it lands his step counts as taken.
    assert fsm.update(Stance.LS, up, 0.3) is Stance.LS
    assert fsm.update(Stance.LS, both, 0.35) is Stance.DS and not fsm.recovery_step
    assert fsm.update(Stance.LS, both, 0.4) is Stance.DS
    # A touch before the minimum swing time does not end a step; the timeout does.
    fsm.update(Stance.DS, both, 0.5)
    fsm.begin_recovery_step("left", 0.6, timeout_s=0.7)
    assert fsm.update(Stance.DS, both, 0.65) is Stance.RS
    assert fsm.update(Stance.DS, {"left": False, "right": True}, 1.2) is Stance.RS
    assert fsm.update(Stance.DS, {"left": False, "right": True}, 1.31) is Stance.DS


def test_a_lift_off_waits_while_the_lifted_foot_is_the_only_one_down():
    """From double stance, the operator lifts his right foot while the character's left is off the ground and its
    right carries it: with MotionConfig.liftoff_needs_other_foot_down the right stays down however long that lasts
    (no weight-shift timeout), and lifts once the left is down; without it, the lift follows him at once."""
    only_right = {"left": False, "right": True}
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12, lift_needs_other_down=True)
    assert fsm.update(Stance.DS, {"left": True, "right": True}, 0.0) is Stance.DS
    for t in (0.1, 0.5, 2.0):
        assert fsm.update(Stance.LS, only_right, t, None, 0.25) is Stance.DS and fsm.waiting_to_lift
    assert fsm.update(Stance.LS, {"left": True, "right": True}, 2.1, None, 0.25) is Stance.LS
    # Neither foot down (a flight): no wait.
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12, lift_needs_other_down=True)
    assert fsm.update(Stance.LS, {"left": False, "right": False}, 0.1, None, 0.25) is Stance.LS
    plain = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    assert plain.update(Stance.LS, only_right, 0.1, None, 0.25) is Stance.LS


# The controller the scenarios below were traced with: the supporting legs' posture and the pelvis at full weight
# (before WholeBodyConfig.stance_leg_tracking_share and single_stance_pelvis_share). Each scenario is one clip and
# seed on which a feature decides a fall; a change of the controller changes which runs fall, so the feature is
# tested where its effect was traced, and the default controller where the test says "default". All of them were
# traced before the pelvis tracked a jump's push (WholeBodyConfig.pelvis_rate_share 0: the regulator alone) and before
# a double stance's unweighted foot was pressed down (press_double_stance_feet).
TRACED = ControlConfig(whole_body=WholeBodyConfig(stance_leg_tracking_share=1.0, single_stance_pelvis_share=1.0,
                                                   recovery_foot_task_weight=0.0, pelvis_rate_share=0.0,
                                                   press_double_stance_feet=False, own_step_push_bound="he_stands"))
# The default controller before WholeBodyConfig.single_stance_pelvis_share (and the recovery foot task, and the
# standing soles' load bound), which the scenarios of the stopping step and the overdue double stance were traced with.
PELVIS_LEVEL = ControlConfig(whole_body=WholeBodyConfig(single_stance_pelvis_share=1.0, recovery_foot_task_weight=0.0,
                                                        pelvis_rate_share=0.0, own_step_push_bound="he_stands",
                                                        standing_sole_min_load_share=0.0))
# ... and the motion stage's balance layer as it was then: recovery steps of 0.6 leg lengths, and a swing the
# operator stops on not yet landed at once (with either, several of the traced falls come later or not at all).
TRACED_MOTION = {"recovery_step_reach_share": 0.6, "recovery_on_stopping_step": False,
                 "recovery_double_stance_overrun": 0.0, "liftoff_capture_behind_m": None, "foot_yaw_control": False,
                 "liftoff_shift_tolerance_m": None, "recovery_landing_without_swing": False,
                 "landing_pelvis_floor_share": 0.0, "recovery_on_reach_limit": False, "recovery_min_stance_s": 0.1,
                 "recovery_cross_clear_m": None, "recovery_touchdown_share": 1.0, "recovery_landing_gap_m": None,
                 "swing_within_reach": False}
# The scenarios traced before MotionConfig.foot_yaw_control run with the feet's twist left where it was (and the
# weight shift from standing, the recovery steps' landing and the step timing as they were then; with the
# controller, the recovery foot task off, and a double stance's unweighted foot not pressed down: NO_FOOT_TASK).
NO_FOOT_TASK = ControlConfig(whole_body=WholeBodyConfig(recovery_foot_task_weight=0.0,
                                                        press_double_stance_feet=False,
                                                        own_step_push_bound="he_stands"))
TWIST_FREE = {"foot_yaw_control": False, "liftoff_shift_tolerance_m": None, "recovery_landing_without_swing": False,
              "landing_pelvis_floor_share": 0.0, "recovery_on_reach_limit": False, "recovery_min_stance_s": 0.1,
              "recovery_ds_on_reach_limit": False, "recovery_cross_clear_m": None, "recovery_touchdown_share": 1.0,
              "recovery_landing_gap_m": None, "swing_within_reach": False}
# The scenarios traced before the shorter double stance between recovery steps (MotionConfig.recovery_min_stance_s),
# the crossover recovery steps (MotionConfig.recovery_cross_clear_m), the earlier touchdown of a recovery step's
# foot (MotionConfig.recovery_touchdown_share), its landing on a corner (MotionConfig.recovery_landing_gap_m) and the
# operator's swing kept within the leg's reach (MotionConfig.swing_within_reach).
WAIT_TRACED = {"recovery_min_stance_s": 0.1, "recovery_cross_clear_m": None, "recovery_touchdown_share": 1.0,
               "recovery_landing_gap_m": None, "swing_within_reach": False}


def _run(spec: str, seconds: float, motion: MotionConfig, seed: int = 0, control: ControlConfig | None = None):
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    opened = open_source(spec, seed=seed, duration_s=seconds)
    cfg = SessionConfig(duration_s=seconds, seed=seed, operator=OperatorConfig(), motion=motion,
                        control=control or TRACED_DIFFERENCED,
                        clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
    session = Session(cfg, opened.source)
    result = session.run()
    opened.source.close()
    return result, session


def test_a_recovery_step_lands_when_its_capture_landing_would_leave_the_legs_reach():
    """Step timing: the capture point runs ahead over the stance sole; the step's swing time shortens to when its
    capture landing reaches the leg's reach (never below recovery_swing_min_s), where the landing then catches the
    capture point on its sole's trailing edge. With the nominal time the landing is held at the reach, short of it."""
    com, vel = np.array([0.15, -0.05, 0.8]), np.array([1.1, 0.0, 0.0])
    stance = ANKLES["right"]
    nominal = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    reach_s = nominal.time_to_reach_limit_s(com, vel, stance, IDENTITY, np.eye(3))
    assert 0.0 < reach_s < nominal.cfg.recovery_swing_s
    # At that time the unlimited landing is exactly at the reach: the landing there is not moved by the limit.
    landing, xi_land = nominal.capture_landing(reach_s, com, vel, stance, IDENTITY, np.eye(3), "left")
    assert np.hypot(*(landing - stance)[:2]) == pytest.approx(nominal.max_step_m, abs=1e-9)
    assert stands_on(xi_land, stance, IDENTITY, landing, np.eye(3))
    late, xi_late = nominal.capture_landing(nominal.cfg.recovery_swing_s, com, vel, stance, IDENTITY, np.eye(3),
                                            "left")
    assert not stands_on(xi_late, stance, IDENTITY, late, np.eye(3))
    # Standing still over the sole the capture landing never leaves the reach; beyond it already, it has left it.
    assert nominal.time_to_reach_limit_s(np.array([0.0, -0.1, 0.8]), np.zeros(3), stance, IDENTITY,
                                         np.eye(3)) == np.inf
    assert nominal.time_to_reach_limit_s(np.array([0.6, -0.1, 0.8]), vel, stance, IDENTITY, np.eye(3)) == 0.0

    for min_s, expected_s in ((None, nominal.cfg.recovery_swing_s), (0.05, reach_s), (0.15, 0.15)):
        stepper = RecoveryStepper(traced_motion(recovery_swing_min_s=min_s), CHAR_LEG_LENGTH_M, G)
        step = stepper.take_over("left", 1.0, np.array([0.0, 0.1, 0.1]))
        stepper.swing_target(1.0, com, vel, stance, IDENTITY, np.eye(3))
        assert step.duration_s == pytest.approx(expected_s)
        assert not stepper.landing_due(1.0 + 0.79 * expected_s)
        assert stepper.landing_due(1.0 + 0.81 * expected_s)
    with pytest.raises(ConfigError):
        MotionConfig(recovery_swing_min_s=0.0)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "02_03.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/02_03.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_run_that_stops_comes_to_rest_on_steps_that_land_before_the_capture_point_leaves_the_reach(monkeypatch):
    """CMU-dev 02_03 (a run; it ends at 1.41 s, then the operator holds his last pose), seed 0, as the development
    suite runs it. The character stops from running speed on recovery steps. With their nominal 0.2 s each landed at
    the leg's reach short of the capture point, and it fell in the rest (measured: at 4.30 s); landing when the
    capture landing reaches the leg's reach, some of them sooner, it comes to rest."""
    from stylesync.motion.recovery_step import RecoveryStepper

    durations: list[float] = []
    end = RecoveryStepper.end

    def recorded(self, time_s):
        if self.step is not None:
            durations.append(self.step.duration_s)
        end(self, time_s)

    monkeypatch.setattr(RecoveryStepper, "end", recorded)
    spec = f"bvh:{MOCAP / 'cmu-dev' / '02_03.bvh'}"
    timed = suite_run(spec, 0, MotionConfig(), TRACED_DIFFERENCED)
    assert not timed.fell
    assert any(d < MotionConfig().recovery_swing_s - 1e-9 for d in durations)
    assert all(d >= MotionConfig().recovery_swing_min_s - 1e-9 for d in durations)
    durations.clear()
    nominal = suite_run(spec, 0, MotionConfig(recovery_swing_min_s=None), TRACED_DIFFERENCED)
    assert nominal.fell and nominal.fall_time_s is not None and nominal.fall_time_s > 1.41
    assert all(d == MotionConfig().recovery_swing_s for d in durations)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_01.bvh is not available")
@pytest.mark.in_place
def test_a_walk_cut_mid_stride_comes_to_rest_with_its_own_last_step():
    """CMU 08_01 ends mid-stride (2.27 s); its operator then holds his last pose. Without the stopping landing and
    recovery steps the character keeps its momentum and falls in the rest (measured: 3.3 s, seed 0)."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_01.bvh'}"
    # Traced with the feet's twist left where it is; with the feet's yaw controlled it does not fall either, but
    # still sways in its last double stance at 0.1-0.17 m/s (measured).
    result, session = _run(spec, 5.27, traced_motion(foot_yaw_control=False))
    assert not result.fell
    com_vel = session.mass.com_velocity(session.backend.read_state(result.sim_duration_s))
    assert float(np.linalg.norm(com_vel[:2])) < 0.05  # at rest at the end
    assert not _run(spec, 5.27, traced_motion())[0].fell
    off, _ = _run(spec, 5.27, traced_motion(recovery_steps=False))
    assert off.fell and off.fall_time_s is not None and off.fall_time_s > 2.27


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_04.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_04.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_swing_he_stops_on_is_landed_at_once_where_the_capture_point_goes(monkeypatch):
    """CMU-dev 08_04 ends (3.99 s) on the operator's right foot; he lowers the raised left one over 0.5 s as he comes
    to rest. The stopping landing moves the character's left foot to catch its capture point, and a recovery step
    takes the swing over at once and lands it there: it comes to rest. Left to his slower lowering of the foot, the
    swing is taken over only after 1.5 of his swing times, with the capture point far out, and it falls in the rest
    (measured, seed 0: taken over at 4.07 s and at rest, against 4.29 s and a fall at 5.24 s)."""
    from stylesync.motion.recovery_step import RecoveryStepper

    taken: list[float] = []
    take_over = RecoveryStepper.take_over

    def recorded(self, side, time_s, swing_ankle_world):
        taken.append(time_s)
        return take_over(self, side, time_s, swing_ankle_world)

    monkeypatch.setattr(RecoveryStepper, "take_over", recorded)
    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_04.bvh'}"
    clip_end_s = 3.99
    result, session = _run(spec, clip_end_s + 3.0, traced_motion(**TWIST_FREE), control=PELVIS_LEVEL)
    assert not result.fell
    assert taken and clip_end_s < taken[0] < clip_end_s + 0.15
    com_vel = session.mass.com_velocity(session.backend.read_state(result.sim_duration_s))
    assert float(np.linalg.norm(com_vel[:2])) < 0.05  # at rest at the end
    taken.clear()
    off, _ = _run(spec, clip_end_s + 3.0, traced_motion(**TWIST_FREE, recovery_on_stopping_step=False),
                  control=PELVIS_LEVEL)
    assert taken and taken[0] > clip_end_s + 0.2
    assert off.fell and off.fall_time_s is not None and off.fall_time_s > clip_end_s


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_05.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_05.bvh is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_double_stance_whose_capture_point_has_run_out_ends_in_a_step_of_its_own(monkeypatch):
    """CMU-dev 07_05, seed 0: the character lands a recovery step (3.63 s) while the operator is still on one foot,
    its step for his counted as taken; he lands (4.0 s) and stands to the clip's end (4.27 s). Its capture point is
    out of its support from the landing on, drifting sideways. Overdue (1.5 of his double stances), a recovery step
    begins while he still walks and it comes to rest; waiting for his standing, the step begins after the clip's
    end and it falls in the rest (measured: 4.08 s against 4.36 s, and a fall at 5.20 s)."""
    from stylesync.motion.recovery_step import RecoveryStepper

    began: list[float] = []
    trigger = RecoveryStepper.trigger

    def recorded(self, time_s, *args, **kwargs):
        step = trigger(self, time_s, *args, **kwargs)
        if step is not None:
            began.append(time_s)
        return step

    monkeypatch.setattr(RecoveryStepper, "trigger", recorded)
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_05.bvh'}"
    clip_end_s = 4.27
    result, _ = _run(spec, clip_end_s + 3.0, traced_motion(**TWIST_FREE), control=PELVIS_LEVEL)
    assert not result.fell
    assert any(3.9 < t < clip_end_s for t in began)
    began.clear()
    off, _ = _run(spec, clip_end_s + 3.0, traced_motion(**TWIST_FREE, recovery_double_stance_overrun=0.0),
                  control=PELVIS_LEVEL)
    assert not any(3.9 < t < clip_end_s for t in began) and any(t > clip_end_s for t in began)
    assert off.fell and off.fall_time_s is not None and off.fall_time_s > clip_end_s


def test_the_fsm_lets_the_balance_land_a_swing_it_takes_over():
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    both, up = {"left": True, "right": True}, {"left": True, "right": False}
    fsm.update(Stance.DS, both, 0.0)
    assert fsm.update(Stance.LS, up, 0.1) is Stance.LS and not fsm.recovery_step  # the operator's step
    fsm.take_over_swing(0.9, timeout_s=0.7)
    # He still holds his foot up, or puts it down: the character's foot lands when it touches, not when he does.
    assert fsm.update(Stance.LS, up, 1.0) is Stance.LS and fsm.recovery_step and not fsm.hold_reference
    assert fsm.update(Stance.DS, up, 1.1) is Stance.LS and not fsm.hold_reference
    assert fsm.update(Stance.LS, both, 1.2) is Stance.DS and not fsm.recovery_step
    assert fsm.update(Stance.LS, both, 1.3) is Stance.DS  # his step counts as taken until he changes stance
    # The timeout runs from the take-over, not from the lift-off.
    fsm.update(Stance.RS, {"left": False, "right": True}, 1.4)
    fsm.take_over_swing(2.0, timeout_s=0.7)
    assert fsm.update(Stance.RS, {"left": False, "right": True}, 2.6) is Stance.RS
    assert fsm.update(Stance.RS, {"left": False, "right": True}, 2.71) is Stance.DS


def test_a_swing_taken_over_in_the_air_is_lowered_from_where_it_is_to_the_capture_landing():
    cfg = traced_motion()
    stepper = RecoveryStepper(cfg, CHAR_LEG_LENGTH_M, G)
    com, vel = np.array([0.12, -0.02, 0.8]), np.array([0.5, 0.0, 0.0])
    raised = np.array([-0.1, 0.1, 0.25])
    step = stepper.take_over("left", 1.0, raised)
    assert step.taken_over and stepper.count == 1
    heights = []
    for t in np.linspace(1.0, 1.0 + cfg.recovery_swing_s, 7):
        target = stepper.swing_target(t, com, vel, ANKLES["right"], IDENTITY, np.eye(3))
        heights.append(target[2])
    assert heights[0] == pytest.approx(raised[2])  # no jump at the take-over
    assert all(b <= a + 1e-12 for a, b in zip(heights, heights[1:], strict=False))  # only down, no second lift
    assert heights[-1] < ANKLE_HEIGHT_M  # pressed onto the ground once the swing time is over
    # It lands ahead of the stance foot, where the forward-moving capture point goes.
    assert step.landing_world[0] > ANKLES["right"][0] + 0.1


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_01.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_late_contact_hold_keeps_the_walk_going():
    """CMU 08_01, seed 1: the character's foot often lands after the operator's (late contact, Sec. 5.1). Held
    reference targets that stop where he was brake the character (measured: a fall at 3.0 s, in the rest after the
    clip); targets that go on at the walk's velocity while the pose is held let it walk the clip and stop. Both
    without the bound on the COM target's capture point (capture_bound.py), which also keeps the stopped targets from
    throwing this run; with everything on, it comes to rest too."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_01.bvh'}"
    on, _ = _run(spec, 5.27, traced_motion(**TWIST_FREE, capture_bound_sole_share=0.0), seed=1, control=TRACED)
    assert not on.fell
    off, _ = _run(spec, 5.27, traced_motion(**TWIST_FREE, late_contact_keeps_momentum=False,
                                           capture_bound_sole_share=0.0), seed=1, control=TRACED)
    assert off.fell
    default, _ = _run(spec, 5.27, traced_motion(), seed=1)
    assert not default.fell


def test_a_sideways_drift_steps_with_the_foot_that_can_catch_it_not_the_one_that_would_cross():
    """Traced at rest after CMU 06_01 (seed 1): the left foot 0.26 m behind the right, the capture point drifting
    out beside the right sole. The nearer sole is the right one, but the left foot cannot land beyond it (never
    across it): its step would leave the capture point outside; the right foot's step out catches it."""
    ankles = {"left": np.array([-0.298, 0.106, ANKLE_HEIGHT_M]), "right": np.array([-0.036, 0.058, ANKLE_HEIGHT_M])}
    com, vel = np.array([-0.073, 0.004, 0.8]), np.array([-0.03, -0.09, 0.0])
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    residual = {stance: stepper.capture_residual_m(com, vel, ankles[stance], IDENTITY, np.eye(3), swing)
                for stance, swing in (("left", "right"), ("right", "left"))}
    assert residual["left"] <= 0.0 < residual["right"]
    step = stepper.trigger(1.0, com, vel, ankles, QUATS, ["left", "right"], np.eye(3))
    assert step is not None and step.side == "right"
    # Without the heading frame the nearer sole is the stance, as before.
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    step = stepper.trigger(1.0, com, vel, ankles, QUATS, ["left", "right"])
    assert step is not None and step.side == "left"


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_01.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_step_lets_the_body_move_as_its_landing_assumes():
    """CMU 07_01, seed 0, in the rest after the clip (2.6 s): the frozen operator's COM is over one of his feet, and
    a COM task pulling the character's there while its recovery step is in the air lands the foot where the capture
    point no longer goes (measured: a fall at 5.2 s). With the COM task holding the character's own state during
    the step, it comes to rest. Both runs leave the body at its height while a step lands (no
    ``recovery_landing_reach``) and the COM target unbounded (no ``capture_bound_sole_share``): with the body lowered
    for a landing as well, both come to rest."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_01.bvh'}"
    free, _ = _run(spec, 5.6, traced_motion(**TWIST_FREE, recovery_landing_reach=False, capture_bound_sole_share=0.0),
                   control=TRACED)
    assert not free.fell
    pulled, _ = _run(spec, 5.6, traced_motion(**TWIST_FREE, recovery_step_free_com=False, recovery_landing_reach=False,
                                             capture_bound_sole_share=0.0), control=TRACED)
    assert pulled.fell and pulled.fall_time_s is not None and pulled.fall_time_s > 2.6


@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_the_walk_goes_the_operators_way_with_its_swing_aimed_at_his_last_landing():
    """The built-in walk, 8 s, seed 0: each swing goes from where the character's foot lifted off to a landing placed
    from its capture point as his last landing was from his, and the character goes his way. Aimed at the offset
    his swing foot has now (far behind his capture point while it swings) and started relative to the stance foot
    as his is, the swing went back before it came forward, and the character walked backwards (measured)."""
    from stylesync.metrics.summary import summarize
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    progress = {}
    for landing in ("his_last_landing", "his_foot_now"):
        opened = open_source("builtin:walk", seed=0, duration_s=8.0)
        cfg = SessionConfig(duration_s=8.0, seed=0, motion=MotionConfig(swing_landing=landing))
        result = Session(cfg, opened.source).run()
        assert not result.fell
        progress[landing] = summarize(result)["path_progress"]
    assert progress["his_last_landing"] > 0.25
    assert progress["his_foot_now"] < 0.0


@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_targets_that_follow_the_operator_keep_the_walk_up_with_him():
    """The built-in walk, 7 s: with the feet-anchored targets the character covers about a third of the operator's
    (scaled) distance, braked at each stance change; with the targets advancing at his velocity it covers most."""
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    covered = {}
    for tau in (0.0, 0.5):
        opened = open_source("builtin:walk", seed=0, duration_s=7.0)
        cfg = SessionConfig(duration_s=7.0, seed=0,
                            motion=traced_motion(**TWIST_FREE, reference_follows_operator_s=tau), control=TRACED)
        session = Session(cfg, opened.source)
        start = {}

        def on_tick(state, ref, session=session, start=start):
            com = session.mass.com(state)
            start.setdefault("com", com.copy())
            start["end"] = com.copy()

        session.on_tick = on_tick
        result = session.run()
        assert not result.fell
        covered[tau] = float(np.linalg.norm((start["end"] - start["com"])[:2]))
    assert covered[0.5] > 2.0 * covered[0.0]
    assert covered[0.5] > 3.0


def test_the_fsm_keeps_a_foot_down_until_the_weight_is_over_the_other_or_the_wait_is_over():
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    both = {"left": True, "right": True}
    fsm.update(Stance.DS, both, 0.0)
    not_right = {"left": True, "right": False}
    assert fsm.update(Stance.LS, both, 0.1, not_right, 0.25) is Stance.DS and fsm.waiting_to_lift
    assert fsm.update(Stance.LS, both, 0.2, not_right, 0.25) is Stance.DS
    assert fsm.update(Stance.LS, both, 0.3, {"left": True, "right": True}, 0.25) is Stance.LS  # weight over
    assert not fsm.waiting_to_lift
    # The wait ends at the limit; an operator back on both feet meanwhile starts the next wait afresh.
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    fsm.update(Stance.DS, both, 0.0)
    assert fsm.update(Stance.RS, both, 0.1, {"left": False, "right": True}, 0.25) is Stance.DS
    assert fsm.update(Stance.DS, both, 0.2, {"left": False, "right": True}, 0.25) is Stance.DS
    assert fsm.update(Stance.RS, both, 0.3, {"left": False, "right": True}, 0.25) is Stance.DS
    assert fsm.update(Stance.RS, both, 0.5, {"left": False, "right": True}, 0.25) is Stance.DS
    assert fsm.update(Stance.RS, both, 0.56, {"left": False, "right": True}, 0.25) is Stance.RS
    # No condition given: the operator's lift-off is followed at once.
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    fsm.update(Stance.DS, both, 0.0)
    assert fsm.update(Stance.LS, both, 0.1) is Stance.LS


@pytest.mark.skipif(not (MOCAP / "cmu" / "131_01.bvh").exists(),
                    reason="../shared/mocap/cmu/131_01.bvh is not available")
@pytest.mark.in_place
def test_a_step_from_standing_waits_for_the_weight_to_shift():
    """CMU 131_01 (a styled walk), seed 0: the operator stands, then lifts his right foot with his capture point over
    his left sole; the character's was 7 cm outside its left sole and it fell sideways off it at 1.9 s. Waiting
    (at most 0.25 s) for the weight to come over, it takes that step and falls later (at 3.05 s). Both runs read
    the operator's stance by his ankles alone (no rear-foot support), so that only the wait differs; with the whole
    balance layer (the default) it falls at 3.44 s."""
    spec = f"bvh:{MOCAP / 'cmu' / '131_01.bvh'}"
    shifted, _ = _run(spec, 3.5, traced_motion(rear_foot_support_margin_m=None, **TRACED_MOTION), control=TRACED)
    at_once, _ = _run(spec, 3.5, traced_motion(liftoff_weight_shift_s=0.0, rear_foot_support_margin_m=None,
                                              **TRACED_MOTION), control=TRACED)
    default, _ = _run(spec, 3.5, traced_motion())
    assert not default.fell or (default.fall_time_s is not None and default.fall_time_s > 3.0)
    assert at_once.fell and at_once.fall_time_s is not None and at_once.fall_time_s < 2.1
    assert not shifted.fell or (shifted.fall_time_s is not None and shifted.fall_time_s > 2.5)


@pytest.mark.in_place
def test_a_kick_waits_until_the_weight_is_over_the_stance_ankle_as_the_operators():
    """The built-in kick in place, seed 0: the operator stands, shifts his weight over his left foot (his capture
    point over his ankle) and kicks with his right. Lifting the foot once its capture point was within 2 cm of the
    inner edge of its left sole (its COM still 9 cm inwards of the ankle), the character fell towards the kicking
    side at 2.4 s. Waiting (at most ``liftoff_weight_shift_s``) until its capture point is within 1 cm of its stance
    ankle, it kicks and stands through 5 s. (With the recovery steps that land, the early lift-off's fall comes later,
    at 3.8 s, against 2.4 s before. Traced before the crossover recovery steps, off here: they catch the early
    lift-off's fall as well.)"""
    spec = "deepmimic:kick"
    then = {"recovery_cross_clear_m": None}
    matched, _ = _run(spec, 5.0, traced_motion(**then))
    edge_only, _ = _run(spec, 5.0, traced_motion(liftoff_shift_tolerance_m=None, **then))
    assert not matched.fell
    assert edge_only.fell
    early, _ = _run(spec, 5.0, traced_motion(liftoff_shift_tolerance_m=None, recovery_landing_without_swing=False,
                                            **then), control=NO_FOOT_TASK)
    assert early.fell and early.fall_time_s is not None and early.fall_time_s < 3.0


@pytest.mark.skipif(not (MOCAP / "deepmimic" / "humanoid3d_stealthy_walk.txt").exists(),
                    reason="../shared/mocap/deepmimic/humanoid3d_stealthy_walk.txt is not available")
@pytest.mark.in_place
def test_a_rear_foot_on_its_toes_is_read_as_still_standing():
    """The stealthy walk's long, low stride (2.6-3.2 s): the rear ankle rises 6-10 cm above the front one while
    its toes stay down and the operator's capture point stays 0.1-0.2 m behind his front heel. Read by ankle heights
    alone he stands on his front foot, and the character lifts its rear foot with its COM behind the front one;
    read with the rear foot bearing weight, both stay down, and the fall comes later. Traced before recovery steps
    were allowed while the character waits with its step counted (``recovery_while_step_counted``): both runs
    without them."""
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    spec = f"deepmimic:{MOCAP / 'deepmimic' / 'humanoid3d_stealthy_walk.txt'}"
    out = {}
    for margin in (None, 0.02):
        opened = open_source(spec, seed=0, duration_s=5.0)
        cfg = SessionConfig(duration_s=5.0, seed=0, motion=traced_motion(rear_foot_support_margin_m=margin,
                                                                         recovery_while_step_counted=False,
                                                                         **TRACED_MOTION),
                            control=TRACED,
                            clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
        session = Session(cfg, opened.source)
        stances: list[Stance] = []

        def on_tick(state, ref, stances=stances, session=session):
            if 2.7 <= state.time_s <= 3.0:
                stances.append(session.reading.operator_stance)

        session.on_tick = on_tick
        result = session.run()
        out[margin] = (stances, result.fall_time_s or 5.0)
    assert Stance.LS in out[None][0]  # ankle heights alone: he stands on his left (front) foot
    assert set(out[0.02][0]) == {Stance.DS}
    assert out[0.02][1] > out[None][1] + 0.2


@pytest.mark.skipif(not (MOCAP / "cmu" / "02_01.bvh").exists(),
                    reason="../shared/mocap/cmu/02_01.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_step_that_must_land_lowers_the_body_until_its_foot_reaches_the_ground():
    """CMU 02_01, seed 2, in the rest after the clip: the first recovery step's landing is near the leg's full
    reach (0.43 m ahead of the stance ankle); with the pelvis at the operator's height the foot hovered 5-10 cm
    above the ground for 0.3 s after its nominal swing while the body ran on, and the character fell at 4.65 s.
    With the pelvis lowered as far as the landing needs (from where the hip is), it comes to rest. Both without the
    bound on the COM target's capture point (capture_bound.py), with which the character, braked in its double
    stances, comes to rest either way."""
    spec = f"bvh:{MOCAP / 'cmu' / '02_01.bvh'}"
    reach, _ = _run(spec, 5.85, traced_motion(capture_bound_sole_share=0.0, **TRACED_MOTION), seed=2, control=TRACED)
    hover, _ = _run(spec, 5.85, traced_motion(recovery_landing_reach=False, capture_bound_sole_share=0.0,
                                             **TRACED_MOTION), seed=2, control=TRACED)
    assert not reach.fell
    assert hover.fell and hover.fall_time_s is not None and hover.fall_time_s > 2.85  # in the rest


def test_a_step_counted_as_taken_leaves_the_character_waiting_in_double_stance():
    fsm = CharacterStanceFsm(late_contact_timeout_s=0.4, min_swing_s=0.12)
    both = {"left": True, "right": True}
    fsm.update(Stance.DS, both, 0.0)
    assert fsm.update(Stance.LS, both, 0.1) is Stance.LS and not fsm.step_counted
    # The swing foot touches before the operator's lands (early contact): his step counts as taken.
    assert fsm.update(Stance.LS, both, 0.3) is Stance.DS and fsm.step_counted
    assert fsm.update(Stance.LS, both, 0.5) is Stance.DS and fsm.step_counted
    assert fsm.update(Stance.DS, both, 0.6) is Stance.DS and not fsm.step_counted


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "05_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/05_01.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_character_waiting_with_its_step_counted_may_still_step_on_its_own():
    """CMU-dev 05_01, seed 2, in the rest after the clip (4.9 s): the operator's held last frame is on one foot,
    lowering the other; the character, its step for his counted as taken, stood on both feet with its capture point
    running 0.2 to 0.65 m out of its support for 0.4 s, and could not step until he stood on both (measured: a fall at
    5.62 s). With recovery steps allowed while it waits, its first one begins while he is still on one foot."""
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    spec = f"bvh:{MOCAP / 'cmu-dev' / '05_01.bvh'}"
    began = {}
    for allowed in (False, True):
        opened = open_source(spec, seed=2, duration_s=5.4)
        cfg = SessionConfig(duration_s=5.4, seed=2,
                            motion=traced_motion(**TWIST_FREE, recovery_while_step_counted=allowed),
                            control=NO_FOOT_TASK,
                            clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
        session = Session(cfg, opened.source)
        steps: list[float] = []
        count = [0]

        def on_tick(state, ref, steps=steps, session=session, count=count):
            motion = session.motion
            if (motion.recovery.count > count[0] and state.time_s > 4.9
                    and motion.reading.operator_stance is not Stance.DS):
                steps.append(state.time_s)  # a recovery step began while he is on one foot
            count[0] = motion.recovery.count

        session.on_tick = on_tick
        session.run()
        opened.source.close()
        began[allowed] = steps
    assert not began[False]
    assert began[True] and began[True][0] < 5.2


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_11.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_11.bvh is not available")
@pytest.mark.in_place
def test_a_rear_foot_stays_down_while_the_capture_point_is_behind_the_front_heel():
    """CMU-dev 07_11, seed 4: the walker sets off from rest with his feet apart. The character, still at rest, lifted
    its rear foot with him while its capture point was behind its front heel: on the front foot alone it could
    only fall back (it fell in the clip on every seed). With the rear foot kept down (at most
    ``liftoff_weight_shift_s``) until the capture point is over the front sole, it walks the clip (2.58 s). (Traced
    before the crossover recovery steps and the step of a double stance beyond a step's reach, off here: they catch
    the lifted rear foot's fall as well.)"""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_11.bvh'}"
    clip_end_s = 2.58
    before = {"recovery_cross_clear_m": None, "recovery_ds_beyond_reach": False}
    kept, _ = _run(spec, clip_end_s, traced_motion(**before), seed=4)
    lifted, _ = _run(spec, clip_end_s, traced_motion(liftoff_capture_behind_m=None, **before), seed=4)
    assert not kept.fell
    assert lifted.fell and lifted.fall_time_s is not None and lifted.fall_time_s < clip_end_s


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "02_03.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/02_03.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_lighter_pelvis_on_one_foot_lets_a_running_stride_swing_forward():
    """CMU-dev 02_03 (a run), seed 0: with the pelvis orientation at full weight in single stance, the first swing
    on the left foot (0.42-0.73 s) goes backwards while the operator's goes forward, lands beside the stance foot,
    and the body sinks and falls in the clip (0.98 s). At ``single_stance_pelvis_share`` 0.3 the swing lands 0.73 m
    ahead of the stance ankle and the run completes, the 3 s rest after the clip included (4.41 s)."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '02_03.bvh'}"
    light, _ = _run(spec, 4.41, traced_motion(**TWIST_FREE))
    level, _ = _run(spec, 4.41, traced_motion(**TWIST_FREE),
                    control=ControlConfig(whole_body=WholeBodyConfig(single_stance_pelvis_share=1.0)))
    assert not light.fell
    assert level.fell and level.fall_time_s is not None and level.fall_time_s < 1.41


def test_the_outward_direction_of_a_capture_point_tells_behind_from_ahead():
    feet = {"left": ANKLES["left"], "right": ANKLES["right"]}
    forward = np.array([1.0, 0.0])
    out, along = support_outside_along(np.array([-0.3, 0.0]), feet, QUATS, ["left", "right"], forward)
    assert out > 0.2 and along == pytest.approx(-1.0)
    out, along = support_outside_along(np.array([0.5, 0.0]), feet, QUATS, ["left", "right"], forward)
    assert out > 0.2 and along == pytest.approx(1.0)
    out, along = support_outside_along(np.array([0.03, 0.0]), feet, QUATS, ["left", "right"], forward)
    assert out < 0.0 and along == 0.0


def test_a_capture_point_out_of_reach_after_the_wait_is_told_from_one_a_step_then_catches():
    """Eq. 21's pendulum in two phases: the centre of pressure in both soles for the wait, then in the stance sole
    for the swing. A capture point 1 cm ahead of the soles, still, stays within a step's reach (0.6 m) after a 0.3 s
    wait and a 0.2 s swing; moving 0.3 m/s it leaves it after that wait, not after none."""
    feet = ["left", "right"]
    com = np.array([FOOT_CENTER_AHEAD_OF_ANKLE_M + FOOT_LENGTH_M / 2 + 0.01, 0.0, 0.8])
    still, moving = np.zeros(3), np.array([0.3, 0.0, 0.0])
    omega = np.sqrt(G / 0.8)
    toes = FOOT_CENTER_AHEAD_OF_ANKLE_M + FOOT_LENGTH_M / 2
    assert toes + 0.01 * np.exp(omega * 0.5) < 0.6 < toes + (0.01 + 0.3 / omega) * np.exp(omega * 0.5)
    assert toes + (0.01 + 0.3 / omega) * np.exp(omega * 0.2) < 0.6
    assert not out_of_reach_after_wait(com, still, G, ANKLES, QUATS, feet, 0.3, 0.2, 0.6)
    assert out_of_reach_after_wait(com, moving, G, ANKLES, QUATS, feet, 0.3, 0.2, 0.6)
    assert not out_of_reach_after_wait(com, moving, G, ANKLES, QUATS, feet, 0.0, 0.2, 0.6)
    # within the soles it never leaves: the centre of pressure holds it
    assert not out_of_reach_after_wait(np.array([0.05, 0.0, 0.8]), still, G, ANKLES, QUATS, feet, 5.0, 0.2, 0.6)


@pytest.mark.skipif(not (MOCAP / "deepmimic" / "humanoid3d_zombie_walk.txt").exists(),
                    reason="../shared/mocap/deepmimic/humanoid3d_zombie_walk.txt is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_double_stance_that_would_wait_out_of_reach_steps_at_once():
    """The DeepMimic zombie walk, seed 1: at 3.67 s the operator lifts his right foot; the character, on both feet,
    has its capture point 8 cm outside them and moving out. Without the rule, its right swing (taken over) landed at
    3.83 s, and it then waited in double stance for his next lift-off, 0.9 s away on a zombie's slow gait, and for
    its double stance to be overdue: its own step began at 4.32 s with the capture point 0.31 m out, and the walk fell
    at 4.74 s (measured). Stepping as soon as the wait for his lift-off would leave the capture point out of a step's
    reach while a step now still catches it (3.67 s), it walks on."""
    spec = f"deepmimic:{MOCAP / 'deepmimic' / 'humanoid3d_zombie_walk.txt'}"

    def run(on: bool):
        """The first recovery step begun from double stance after 3.4 s (start time [s]; a swing of his taken over
        is not one), and the result."""
        starts: list[float] = []

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is not None and step.start_s > 3.4 and not step.taken_over and not starts:
                    starts.append(step.start_s)
            return on_tick

        # traced without crossing, and with the touchdown at the swing's end
        motion = traced_motion(recovery_ds_on_reach_limit=on, recovery_cross_clear_m=None, recovery_touchdown_share=1.0,
                              recovery_landing_gap_m=None)
        result = suite_run(spec, 1, motion, TRACED_BEFORE_LANDING_WEIGHT, watch=watch)
        return starts, result

    at_once, result = run(True)
    waiting, result_waiting = run(False)
    assert at_once and 3.6 < at_once[0] < 3.7  # measured: 3.67 s
    assert waiting and waiting[0] > 4.2  # measured: 4.32 s
    assert not result.fell
    assert result_waiting.fell and result_waiting.fall_time_s is not None and result_waiting.fall_time_s < 5.0


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "10_04.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/10_04.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_capture_point_behind_both_feet_steps_back_at_once():
    """CMU-dev 10_04, seed 0: a stopping step landed the character's feet side by side with its COM 9 cm behind them
    (1.57 s); the operator walks on forwards. Its capture point ran out behind both feet while it waited for his
    next lift-off and then for the double stance to be overdue (the step back began at 2.08 s, 0.38 m out), and it fell
    backwards in the clip (2.72 s). Stepping back as soon as the capture point is behind, it walks on. (Traced with
    the recovery steps' landing and swing foot as they were then: with the recovery foot task and the carried capture
    point, the waiting character does not fall either; so does it with the double stance's reach rule,
    ``recovery_ds_on_reach_limit``, which steps it at once as well.)"""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '10_04.bvh'}"
    then = {"recovery_landing_without_swing": False, "recovery_ds_on_reach_limit": False}
    at_once, session = _run(spec, 4.0, traced_motion(**then), control=NO_FOOT_TASK)
    assert not at_once.fell
    waiting, _ = _run(spec, 4.0, traced_motion(**then, recovery_step_behind_cos=None), control=NO_FOOT_TASK)
    assert waiting.fell and waiting.fall_time_s is not None and waiting.fall_time_s < 3.0


def test_the_com_velocity_with_a_leg_carried_leaves_out_only_the_legs_own_motion():
    from stylesync.model.character import LINK_NAMES
    from stylesync.model.state import MassProperties

    n = len(LINK_NAMES)
    mass = MassProperties(np.linspace(1.0, 5.0, n))
    leg = tuple(LINK_NAMES.index(f"left_{j}") for j in ("hip", "knee", "ankle"))
    root = LINK_NAMES.index("root")

    class _State:
        link_com_vel_world = np.tile([0.5, -0.2, 0.1], (n, 1))

    state = _State()
    # The leg moving with the pelvis: nothing to leave out.
    assert np.allclose(mass.com_velocity_carried(state, leg, root), mass.com_velocity(state))  # type: ignore[arg-type]
    # The leg swinging sideways at 3 m/s relative to the pelvis: that share of the momentum is left out.
    state.link_com_vel_world = state.link_com_vel_world.copy()
    state.link_com_vel_world[list(leg), 1] += 3.0
    share = float(mass.link_mass_kg[list(leg)].sum() / mass.total_kg)
    assert mass.com_velocity(state)[1] == pytest.approx(-0.2 + 3.0 * share)  # type: ignore[arg-type]
    assert np.allclose(mass.com_velocity_carried(state, leg, root), [0.5, -0.2, 0.1])  # type: ignore[arg-type]



@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "09_06.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/09_06.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_the_swing_foot_of_a_recovery_step_follows_its_target():
    """CMU-dev 09_06 (a run, seed 0) steps on its own from 0.96 s. Through the joint posture alone the swing ankle
    trailed its target by 0.2-0.3 m at mid-swing (traced); the recovery foot task keeps it close. Run with the step
    timing it was traced with (with ``recovery_on_reach_limit`` the run's swings are taken over in the air)."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '09_06.bvh'}"

    def lag(control: ControlConfig) -> float:
        gaps: list[float] = []

        def on_tick(state, ref):
            if ref.recovery_ankle_world and 0.9 <= state.time_s <= 1.3:
                for side, target in ref.recovery_ankle_world.items():
                    ankle = state.link_origin_world[state.link(f"{side}_ankle")]
                    gaps.append(float(np.linalg.norm(ankle[:2] - target[:2])))
            if state.time_s > 1.3:
                raise _Stop

        try:
            suite_run(spec, 0, traced_motion(landing_pelvis_floor_share=0.0, recovery_on_reach_limit=False,
                                            swing_within_reach=False), control,
                       on_tick)
        except _Stop:
            pass
        assert len(gaps) > 10
        return float(np.mean(gaps))

    with_task, without = lag(ControlConfig()), lag(NO_FOOT_TASK)
    assert without > 0.1
    assert with_task < 0.7 * without  # measured: 0.08 m against 0.13 m (mean), 0.15 against 0.26 (max)


class _Stop(Exception):
    pass


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "03_02.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/03_02.bvh is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_recovery_steps_that_land_where_the_body_will_be_keep_a_walk_on_rough_ground_up():
    """CMU-dev 03_02 (walking over uneven ground, seed 1) fell 2.2 s in with the recovery step's foot driven by the
    joint posture alone and its landing planned on the capture point its own swing moved (measured)."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '03_02.bvh'}"
    assert not suite_run(spec, 1, traced_motion(**WAIT_TRACED), TRACED_BEFORE_PRESS).fell
    old = suite_run(spec, 1, traced_motion(recovery_landing_without_swing=False, **WAIT_TRACED), NO_FOOT_TASK)
    assert old.fell


def test_the_pelvis_floor_share_is_checked():
    with pytest.raises(ConfigError):
        traced_motion(landing_pelvis_floor_share=1.5)
    with pytest.raises(ConfigError):
        traced_motion(landing_pelvis_floor_share=-0.1)


@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_landing_foot_out_of_reach_does_not_put_the_pelvis_target_on_the_ground():
    """The kick in place, seed 1 (the development suite's run): from 2.2 s the kicking foot is held for its late
    contact while the operator's pelvis target is 0.45 m to the side of the body. Measured from there, the foot is
    beyond the leg's reach, and the pelvis target went down to the foot's own height; the character fell at 4.9 s.
    The pelvis is now lowered no further than ``landing_pelvis_floor_share`` of the reach above the foot."""

    def lowest_pelvis_target(motion: MotionConfig) -> tuple[float, bool]:
        heights: list[float] = []

        def on_tick(state, ref):
            if 2.1 <= state.time_s <= 2.45:
                heights.append(float(ref.pelvis_world[2]))

        # traced before the bound on the push of the character's own steps (WholeBodyConfig.own_step_push_bound)
        result = suite_run("deepmimic:kick", 1, motion, ControlConfig(whole_body=WholeBodyConfig(
            own_step_push_bound="off")), on_tick)
        assert len(heights) > 20
        return min(heights), result.fell

    low, fell = lowest_pelvis_target(traced_motion(**WAIT_TRACED))
    low_old, fell_old = lowest_pelvis_target(traced_motion(landing_pelvis_floor_share=0.0, **WAIT_TRACED))
    assert low_old < 0.3
    assert low > 0.45
    assert fell_old and not fell


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "09_06.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/09_06.bvh is not available")
@pytest.mark.in_place
def test_an_operator_swing_is_aimed_within_the_legs_reach():
    """CMU-dev 09_06 (a run, seed 1): placed as the runner's are, relative to his capture point and his stance foot,
    the slower character's swing feet were aimed up to 2.3 m from their hip (measured), beyond where the leg can
    land them even with the pelvis at its landing floor; the run fell 0.3 s after its clip's end. Aimed within that
    reach (``swing_within_reach``), the feet land and the run completes its rest."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '09_06.bvh'}"
    floor = traced_motion().landing_pelvis_floor_share * LANDING_REACH * CHAR_LEG_LENGTH_M
    reach = float(np.sqrt((LANDING_REACH * CHAR_LEG_LENGTH_M) ** 2 - floor ** 2))

    def run(within: bool):
        far: list[float] = []

        def watch(session):
            aim = session.motion._swing_target

            def recording(tick, state, side):
                target = aim(tick, state, side)
                hip = state.link_origin_world[state.link(f"{side}_hip")]
                far.append(float(np.linalg.norm(target[:2] - hip[:2])))
                return target

            session.motion._swing_target = recording

        result = suite_run(spec, 1, traced_motion(swing_within_reach=within), ControlConfig(), watch=watch)
        return max(far), result

    far, result = run(True)
    far_old, result_old = run(False)
    assert far_old > 2.0 and result_old.fell
    assert far <= reach + 1e-9 and not result.fell


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_11.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_11.bvh is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_swing_that_would_land_out_of_reach_is_landed_by_the_balance():
    """CMU-dev 07_11 (a walk, seed 1): from 1.89 s the character, faster than its operator, stands on its right foot
    while his left swing goes on at his pace. Followed to his landing, it vaulted over its stance foot: the pelvis
    sank 0.14 m below its target and the walk fell at 2.9 s (measured). Predicted at his usual landing time, the
    capture point is beyond a recovery step's reach, so the swing is taken over at once. (Traced before the double
    stance's reach rule, ``recovery_ds_on_reach_limit``, which is off here.)"""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_11.bvh'}"

    def run(flag: bool):
        taken: list[float] = []
        sink: list[float] = []

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is not None and step.taken_over and step.start_s not in taken:
                    taken.append(step.start_s)
                if 1.8 <= state.time_s <= 2.5:
                    sink.append(float(ref.pelvis_world[2] - state.root_pos_world[2]))
            return on_tick

        result = suite_run(spec, 1, traced_motion(recovery_on_reach_limit=flag, recovery_ds_on_reach_limit=False),
                            ControlConfig(), watch=watch)
        return taken, max(sink), result.fall_time_s or 12.0

    taken, sink, fall = run(True)
    taken_old, sink_old, fall_old = run(False)
    assert taken and 1.85 <= taken[0] <= 1.95  # measured: 1.89 s, as his swing begins
    assert not any(t < 2.5 for t in taken_old)
    assert sink < 0.05 and sink_old > 0.1  # measured: 0.007 m against 0.136 m
    assert fall > fall_old + 1.0  # measured: 4.3 s against 2.9 s


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "09_01.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/09_01.bvh is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_swing_past_its_usual_time_is_landed_before_the_capture_point_runs_out_of_reach():
    """CMU-dev 09_01 (a run), seed 7: the clip ends at 1.20 s with the operator on his right foot, his left foot
    raised and then lowered slowly (the held last frame). His usual swing time is past from about 1.27 s, and his
    landing is predicted for now: the capture point is not yet beyond a recovery step's reach from the stance ankle,
    so the swing waited until 1.385 s, with the capture point 0.49 m outside the stance sole, and the run fell in the
    rest at 2.25 s (measured while the held pose stretched his raised leg; since it keeps its lengths it does not).
    Predicted a recovery swing ahead (``recovery_overdue_swing_horizon``), the swing is taken over at 1.323 s, 0.38 m
    outside, and the run comes to rest."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '09_01.bvh'}"

    def run(flag: bool):
        """The take-overs after the clip's end (start time [s], capture point outside the stance sole [m]) and the
        result."""
        taken: list[tuple[float, float]] = []

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is None or not step.taken_over or step.start_s < 1.2 or step.start_s in dict(taken):
                    return
                xi, _ = capture_point(session.mass.com(state), session.mass.com_velocity(state),
                                      session.motion.g)
                stance = LINK_NAMES.index(f"{'left' if step.side == 'right' else 'right'}_ankle")
                taken.append((step.start_s, sole_outside_m(xi, state.link_origin_world[stance],
                                                           state.link_quat_wxyz[stance])))
            return on_tick

        # traced before the joints' no-load speed (with it, the late swing's run also comes to rest), before Eq.
        # 10's fraction from the rear foot to the front one after the character's own step (with it, too), before
        # a recovery step's timing adapted to its reach (with it, too) and before the held pose kept his leg's
        # lengths (sources/held_pose.py; with it, too: the fall is no longer asserted)
        control = ControlConfig(whole_body=WholeBodyConfig(joint_speed_limit_rad_s=None,
                                                           recovery_foot_target_rate="differenced",
                                                           press_double_stance_feet=False))
        motion = MotionConfig(recovery_overdue_swing_horizon=flag, fraction_needs_feet_in_his_order=False,
                              swing_landing_within_reach=False,
                              recovery_swing_min_s=None)
        return taken, suite_run(spec, 7, motion, control, watch=watch)

    taken, result = run(True)
    taken_old, result_old = run(False)
    assert 1.30 <= taken[0][0] <= 1.35 and taken[0][1] < 0.42  # measured: 1.323 s, 0.376 m
    assert taken_old[0][0] >= 1.37 and taken_old[0][1] > 0.45  # measured: 1.385 s, 0.490 m
    assert not result.fell  # (the late swing fell at 2.25 s while the held pose stretched his raised leg)


@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_step_just_short_of_its_crossover_clearance_lands_on_the_capture_points_side():
    """The built-in spin, seed 0: the operator leaps forward and to the right while he turns. At 2.51 s the
    character stands on its right foot with the capture point ahead of it and to its right, and its left foot steps.
    The landing was planned 12 cm ahead of the right ankle in the heading frame, which turns with the operator's root
    (35° then, the right sole 17°), 3 cm short of the crossover clearance, and so was moved outwards, to the left: the
    foot went back to (-0.12, -0.07) m, and when it landed at 2.72 s the capture point was 0.19 m outside both soles
    (measured). With the clearance taken in the stance sole's own frame (``recovery_cross_stance_frame``) and a
    landing short of it moved to the nearer place off the stance foot (``recovery_cross_nearest``), the foot crosses
    in front of the right one to (0.42, -0.27) m and the landing catches the capture point (0.05 m inside). The spin
    still falls later, when the operator's turning leaps outrun the character's steps."""

    def run(motion: MotionConfig):
        """(the first recovery step begun between 2.4 and 2.6 s: its side, its foot's horizontal position at its end
        [m], how far the capture point is then outside the soles on the ground [m])."""
        found: dict = {}

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is not None and "side" not in found and 2.4 <= step.start_s <= 2.6:
                    found["side"] = step.side
                elif step is None and "side" in found and "xi_out_m" not in found:
                    ankles = {s: state.link_origin_world[LINK_NAMES.index(f"{s}_ankle")] for s in ("left", "right")}
                    quats = {s: state.link_quat_wxyz[LINK_NAMES.index(f"{s}_ankle")] for s in ("left", "right")}
                    xi, _ = capture_point(session.mass.com(state), session.mass.com_velocity(state),
                                          session.motion.g)
                    found["foot_xy"] = ankles[found["side"]][:2].copy()
                    found["xi_out_m"] = support_outside_m(xi, ankles, quats, soles_on_ground(state) or ["left"])
            return on_tick

        suite_run("builtin:spin", 0, motion, TRACED_BEFORE_PRESS, watch=watch)
        return found

    # Traced before a foot in the air nearer the capture point was left to land (recovery_landing_foot_waits): the
    # left foot, over the right sole and a centimetre nearer the capture point, now lands first and the right steps;
    # and before his raised rear foot was read through a band.
    new = run(MotionConfig(recovery_landing_foot_waits=False, swing_landing_within_reach=False,
                           rear_foot_support_hysteresis_m=0.0))
    old = run(MotionConfig(recovery_landing_foot_waits=False, swing_landing_within_reach=False,
                           rear_foot_support_hysteresis_m=0.0, recovery_cross_nearest=False,
                           recovery_cross_stance_frame=False))
    assert new["side"] == old["side"] == "left"
    assert new["foot_xy"][0] > 0.3 and old["foot_xy"][0] < 0.0  # measured: 0.42 m ahead; 0.12 m behind
    assert new["xi_out_m"] < 0.0 < 0.1 < old["xi_out_m"]  # measured: -0.05 m; 0.19 m


@pytest.mark.skipif(not (MOCAP / "deepmimic" / "humanoid3d_stealthy_walk.txt").exists(),
                    reason="../shared/mocap/deepmimic/humanoid3d_stealthy_walk.txt is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_the_next_recovery_step_begins_while_both_soles_are_down():
    """The DeepMimic stealthy walk, seed 2: a recovery step's right foot lands at 3.49 s with the capture point 4 cm
    outside the soles and moving out to the left. With 0.1 s of double stance kept before the next step, the right
    sole unloaded again meanwhile (3.53 s); the next step then had only the left sole to stand on and lifted the right
    foot, which cannot land across the left one, and the walk fell at 4.67 s (measured). After 0.03 s both soles are
    still down, and the left foot steps out."""
    spec = f"deepmimic:{MOCAP / 'deepmimic' / 'humanoid3d_stealthy_walk.txt'}"

    def run(wait_s: float):
        """The recovery steps begun (start time [s], swing side, soles on the ground then), and the result."""
        steps: list[tuple[float, str, int]] = []

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if step is not None and (not steps or steps[-1][0] != step.start_s):
                    steps.append((step.start_s, step.side, len(soles_on_ground(state))))
            return on_tick

        result = suite_run(spec, 2, traced_motion(recovery_min_stance_s=wait_s), TRACED_BEFORE_PRESS, watch=watch)
        return [x for x in steps if 3.49 < x[0] < 3.7], result

    after, result = run(traced_motion().recovery_min_stance_s)
    after_old, result_old = run(0.1)
    # measured: 3.53 s, the left foot, both soles down; with 0.1 s, 3.60 s, the right foot, the left sole alone
    assert after and after[0][1] == "left" and after[0][2] == 2 and after[0][0] < 3.55
    assert after_old and after_old[0][1] == "right" and after_old[0][2] == 1 and after_old[0][0] > 3.58
    assert result_old.fell and not result.fell


def test_the_swing_profiles_velocity_is_its_targets_rate_with_the_landing_held():
    """RecoveryStep.target_vel_world, set by swing_target, is the time derivative of the target for the landing as
    planned this tick: with the capture point on the stance sole the landing stays where it is, and the velocity is
    the targets' central difference, rising, over the landing, coming down, and for a step that took over a swing
    already in the air."""
    stepper = RecoveryStepper(traced_motion(), CHAR_LEG_LENGTH_M, G)
    com, vel = np.array([0.05, 0.1, 0.8]), np.zeros(3)  # over the left sole, at rest: the landing does not move
    swing_s, h = stepper.cfg.recovery_swing_s, 1e-5
    for taken_over in (False, True):
        lift_off = ANKLES["right"] + (np.array([0.0, 0.0, 0.08]) if taken_over else 0.0)
        stepper.step = RecoveryStep("right", 1.0, lift_off.copy(), lift_off.copy(), swing_s, taken_over=taken_over,
                                    lowered=taken_over)
        rates = []
        for phase in (0.1, 0.3, 0.5, 0.7, 0.85, 0.95):
            t = 1.0 + phase * swing_s
            ahead = stepper.swing_target(t + h, com, vel, ANKLES["left"], IDENTITY, np.eye(3))
            behind = stepper.swing_target(t - h, com, vel, ANKLES["left"], IDENTITY, np.eye(3))
            stepper.swing_target(t, com, vel, ANKLES["left"], IDENTITY, np.eye(3))
            rates.append(np.linalg.norm(stepper.step.target_vel_world))
            assert np.allclose(stepper.step.target_vel_world, (ahead - behind) / (2 * h), atol=1e-4), phase
        assert max(rates) > 0.5  # the foot moves (0.2 s to its landing beside the left foot)
    with pytest.raises(ConfigError, match="recovery_foot_target_rate"):
        WholeBodyConfig(recovery_foot_target_rate="finite")


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_foot_follows_its_swing_profiles_velocity_not_the_landings_replanning():
    """The humanoid3d run, seed 14, as the suite runs it. Each tick a recovery step's landing is planned again on the
    capture point, which the swing leg's own reaction moves; with the foot task's target velocity differenced from
    tick to tick, those re-plannings alternated each tick once its landing was due (the target 0.05 m back and forth,
    +-5 m/s), the task asked the leg for +-300 m/s² horizontally, the hip saturated, and the foot went up instead of
    down: it stayed 5-17 cm above the ground for 0.4 s past its due landing, and the run fell at 4.48 s (measured: the
    target velocity reversed at more than 2 m/s on 52 ticks). At the swing profile's own velocity, for the landing as
    planned this tick, no tick reverses, and the run completes. Traced with the pelvis height's regulator alone
    (WholeBodyConfig.pelvis_rate_share 0)."""

    def run(rate: str):
        reversals = [0]
        last: dict[str, np.ndarray | None] = {}

        def watch(session):
            feet = session.controller.recovery_feet

            def tick(state, ref):
                for side, task in feet.items():
                    vel = task.target_vel_world[:2].copy() if task.active else None
                    before = last.get(side)
                    if vel is not None and before is not None and np.linalg.norm(vel) > 2.0 and vel @ before < 0:
                        reversals[0] += 1
                    last[side] = vel
            return tick

        control = ControlConfig(whole_body=WholeBodyConfig(recovery_foot_target_rate=rate, pelvis_rate_share=0.0))
        result = suite_run("builtin:run", 14, MotionConfig(swing_landing_within_reach=False), control, watch=watch)
        return reversals[0], result

    (differenced, fell), (profile, completed) = run("differenced"), run("profile")
    assert differenced > 20 and fell.fell and fell.fall_time_s < 5.0
    assert profile == 0 and not completed.fell


def test_the_swing_target_is_back_at_the_ground_by_the_touchdown_share():
    com, vel = np.array([0.1, 0.03, 0.8]), np.array([0.45, 0.05, 0.0])
    heights = {}
    for share in (0.9, 1.0):
        stepper = RecoveryStepper(traced_motion(recovery_touchdown_share=share), CHAR_LEG_LENGTH_M, G)
        stepper.trigger(1.0, com, vel, ANKLES, QUATS, ["left", "right"])
        swing_s = stepper.cfg.recovery_swing_s
        heights[share] = [stepper.swing_target(1.0 + phase * swing_s, com, vel, ANKLES["left"], IDENTITY,
                                               np.eye(3))[2] for phase in (0.45, 0.5, 0.95)]
    assert heights[1.0][1] == pytest.approx(ANKLE_HEIGHT_M + traced_motion().recovery_step_height_m)  # top at 0.5
    assert heights[0.9][0] == pytest.approx(ANKLE_HEIGHT_M + traced_motion().recovery_step_height_m)  # at 0.45
    assert heights[1.0][2] > ANKLE_HEIGHT_M  # still coming down
    assert heights[0.9][2] < ANKLE_HEIGHT_M  # down already, aimed below the ground
    with pytest.raises(ConfigError):
        traced_motion(recovery_touchdown_share=0.0)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "07_11.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/07_11.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_recovery_steps_that_touch_down_on_time_stop_a_walk():
    """CMU-dev 07_11 (a walk, seed 2) stops in the rest after its clip (from 2.58 s) with steps of its own. With the
    foot target at the ground only at the swing's end, the feet trailed it and touched down late (its three recovery
    steps lasted 0.32, 0.60 and 0.23 s against the nominal 0.2 s), and the walk fell at 2.78 s (measured). Brought
    down by 0.9 of the swing, the feet touch down sooner (five steps, 0.23 s at the median), and the walk comes to
    rest."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '07_11.bvh'}"

    def run(share: float):
        durations: list[float] = []
        started: list[float] = []

        def on_tick(state, ref):
            if ref.recovery_ankle_world and not started:
                started.append(state.time_s)
            elif not ref.recovery_ankle_world and started:
                durations.append(state.time_s - started.pop())

        result = suite_run(spec, 2, traced_motion(recovery_touchdown_share=share, recovery_landing_gap_m=None),
                           TRACED_BEFORE_LANDING_WEIGHT, on_tick)
        return durations, result

    durations, result = run(0.9)
    durations_late, result_late = run(1.0)
    assert durations and durations_late
    assert float(np.median(durations)) < float(np.median(durations_late))
    assert not result.fell
    assert result_late.fell and result_late.fall_time_s is not None and result_late.fall_time_s > 2.58  # in the rest


def test_a_landing_gap_must_be_positive():
    with pytest.raises(ConfigError, match="recovery_landing_gap_m"):
        traced_motion(recovery_landing_gap_m=0.0)


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_08.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_08.bvh is not available")
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_step_that_reaches_the_ground_on_a_corner_has_landed():
    """CMU-dev 08_08 (a fast walk, seed 3). Counted as landed only once it pressed the ground with 5 N, the recovery
    step begun at 2.34 s lasted 0.43 s against its nominal 0.2 s: from 2.61 s its foot rested on a corner of its sole
    (within 3 mm of the ground, tilted, pressing less than that) while the straight stance leg held the pelvis 7 cm
    above its target (measured). Counted as landed once its sole reaches the ground after its horizontal travel, no
    recovery step of the run lasts more than 0.25 s."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_08.bvh'}"
    side_ankle = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}

    def run(gap: float | None):
        durations: list[float] = []
        started: list[float] = []
        resting: list[float] = []  # ticks of a recovery step with its sole within 3 mm of the ground, not pressing

        def watch(session):
            def on_tick(state, ref):
                step = session.motion.recovery.step
                if ref.recovery_ankle_world and not started:
                    started.append(state.time_s)
                elif not ref.recovery_ankle_world and started:
                    durations.append(state.time_s - started.pop())
                if step is not None and not state.feet_pressing()[step.side]:
                    a = side_ankle[step.side]
                    corners = sole_corners_world(state.link_origin_world[a], state.link_quat_wxyz[a])
                    if corners[:, 2].min() < 0.003:
                        resting.append(state.time_s)
            return on_tick

        result = suite_run(spec, 3, traced_motion(recovery_landing_gap_m=gap, swing_within_reach=False),
                           TRACED_BEFORE_LANDING_WEIGHT, watch=watch)
        return durations, resting, result

    durations, _, result = run(traced_motion().recovery_landing_gap_m)
    durations_force, resting_force, result_force = run(None)
    assert not result.fell and not result_force.fell
    assert max(durations_force) > 0.4
    assert len([t for t in resting_force if 2.6 < t < 2.8]) / SessionConfig().clocks.control_hz > 0.1
    assert durations and max(durations) < 0.25


@pytest.mark.skipif(not (MOCAP / "cmu-dev" / "08_08.bvh").exists(),
                    reason="../shared/mocap/cmu-dev/08_08.bvh is not available")
@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_recovery_step_whose_landing_is_due_is_pressed_onto_the_ground():
    """CMU-dev 08_08, seed 1, in the rest after the clip: with the recovery foot's task at its swing weight after the
    landing is due (its target below the ground), a step's foot hovered above the ground from 2.83 s while the body
    sank onto the folding swing leg, and the run fell at 3.11 s (measured: waits of 0.11, 0.16 and then 0.28 s).
    Weighed WholeBodyConfig.recovery_foot_landing_weight once due, every landing touches within 0.1 s (0.06 and
    0.08 s) and the run stands. Traced with landings short of the crossover clearance moved outwards in the heading
    frame (MotionConfig.recovery_cross_nearest and recovery_cross_stance_frame off; with the first, one of three
    landings waits 0.29 s, and the run stands), before the joints' no-load speed (with it, no recovery step of this
    run has a landing falling due), with Eq. 10's fraction by side after a step of the character's own
    (MotionConfig.fraction_needs_feet_in_his_order off), and with every recovery step's nominal time
    (MotionConfig.recovery_swing_min_s None: a step shortened to land before the capture point leaves the reach is due
    sooner, while its foot is still on its way, and that configuration's landings then wait up to 0.17 s), and before
    a lift-off waited for the other foot to be down (MotionConfig.liftoff_needs_other_foot_down off), and before the
    pelvis tracked a jump's push (WholeBodyConfig.pelvis_rate_share 0), and while a lift-off onto a sole the capture
    point has passed waited only the weight shift's time (MotionConfig.liftoff_behind_waits off)."""
    spec = f"bvh:{MOCAP / 'cmu-dev' / '08_08.bvh'}"

    def run(landing_weight: float):
        """The times between a recovery step's landing falling due and its foot touching [s], the last still waiting
        at the run's end (or fall) included, and the result."""
        waits: list[float] = []
        due_since: list[float] = []
        last_tick_s = [0.0]

        def on_tick(state, ref):
            due = any(recovery_landing_due(t) for t in (ref.recovery_ankle_world or {}).values())
            if due and not due_since:
                due_since.append(state.time_s)
            elif not due and due_since:
                waits.append(state.time_s - due_since.pop())
            last_tick_s[0] = state.time_s

        result = suite_run(spec, 1, MotionConfig(recovery_cross_nearest=False, recovery_cross_stance_frame=False,
                                                 swing_landing_within_reach=False,
                                                 fraction_needs_feet_in_his_order=False, recovery_swing_min_s=None,
                                                 liftoff_needs_other_foot_down=False, liftoff_behind_waits=False),
                           ControlConfig(whole_body=WholeBodyConfig(recovery_foot_landing_weight=landing_weight,
                                                                        pelvis_rate_share=0.0,
                                                                        recovery_foot_target_rate="differenced",
                                                                    joint_speed_limit_rad_s=None,
                                                                    own_step_push_bound="off")),
                           on_tick=on_tick)
        if due_since:
            waits.append(last_tick_s[0] - due_since[0])
        return waits, result

    swing_weight = WholeBodyConfig().recovery_foot_task_weight
    waits, result = run(WholeBodyConfig().recovery_foot_landing_weight)
    waits_light, result_light = run(swing_weight)
    assert waits and max(waits) < 0.1
    assert not result.fell
    assert max(waits_light) > 0.25
    assert result_light.fell and result_light.fall_time_s is not None and result_light.fall_time_s < 3.5


def test_the_recovery_foot_landing_weight_is_checked():
    with pytest.raises(ConfigError):
        WholeBodyConfig(recovery_foot_landing_weight=-1.0)

"""The bound on the COM target's capture point (motion/capture_bound.py)."""

from pathlib import Path

import numpy as np
import pytest
from conftest import TRACED_BEFORE_LANDING_WEIGHT, TRACED_DIFFERENCED

from stylesync.config import ConfigError, MotionConfig, OperatorConfig, SessionConfig
from stylesync.model.character import ANKLE_HEIGHT_M
from stylesync.model.sole import (
    convex_hull_points,
    convex_hull_xy,
    outside_distance_m,
    outside_distance_points,
    sole_corner_points,
    sole_corners_in_foot,
    sole_corners_world,
    sole_points_xy,
)
from stylesync.motion.capture_bound import bounded_com_target, gait_capture_margin_m, landing_catch_region
from stylesync.motion.recovery_step import capture_point

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
OMEGA = 3.5
FEET = [(np.array([0.0, 0.09, ANKLE_HEIGHT_M]), IDENTITY), (np.array([0.0, -0.09, ANKLE_HEIGHT_M]), IDENTITY)]


def _soles(feet, share):
    return [sole_points_xy(a, q, sole_corner_points(share)) for a, q in feet]


def _xi(com, vel):
    return com[:2] + vel[:2] / OMEGA


def _outside(point, soles, share):
    hull = convex_hull_xy(np.vstack([sole_corners_world(a, q, sole_corners_in_foot(share))[:, :2] for a, q in soles]))
    return outside_distance_m(point, hull)[0]


def test_a_target_whose_capture_point_is_over_the_feet_is_left_as_it_is():
    com, vel = np.array([0.02, 0.0, 0.85]), np.array([0.1, 0.05, 0.0])
    out_com, out_vel = bounded_com_target(com, vel, OMEGA, _soles(FEET, 0.8))
    assert out_com is com and out_vel is vel
    fast = 10 * vel
    out_com, out_vel = bounded_com_target(com, fast, OMEGA, [])
    assert out_com is com and out_vel is fast  # no soles: nothing to bound by


def test_a_target_leaning_past_the_toes_becomes_a_body_standing_at_the_shrunk_edge():
    """A punch's lunge: the target 0.2 m ahead of the ankles, moving on at 0.8 m/s."""
    com, vel = np.array([0.2, 0.0, 0.8]), np.array([0.8, 0.0, 0.1])
    assert _outside(_xi(com, vel), FEET, 1.0) > 0.25
    out_com, out_vel = bounded_com_target(com, vel, OMEGA, _soles(FEET, 0.8))
    assert out_vel[:2] == pytest.approx([0.0, 0.0]) and out_vel[2] == pytest.approx(0.1)
    assert out_com[2] == pytest.approx(0.8)
    xi = _xi(out_com, out_vel)
    assert _outside(xi, FEET, 0.8) == pytest.approx(0.0, abs=1e-12)  # on the shrunk polygon's edge
    assert _outside(xi, FEET, 1.0) < -0.01  # within the whole soles, with a margin
    assert xi[1] == pytest.approx(0.0)  # straight ahead: the nearest point of the front edge


def test_the_bounded_target_is_continuous_as_its_capture_point_crosses_the_edge():
    """The COM force (the PD of Eq. 16 with the capture-point gains) changes smoothly with the target: no jump as
    ξ_d leaves the polygon, and the full cut only beyond the band."""
    kp, kd = OMEGA ** 2, 2 * OMEGA
    vel = np.array([0.9, 0.0, 0.0])
    front = max(float(sole_corners_world(a, q, sole_corners_in_foot(0.8))[:, 0].max()) for a, q in FEET)
    forces, bounded = [], []
    for d in np.linspace(-0.01, 0.01, 201):  # ξ_d from 1 cm inside the shrunk front edge to 1 cm outside it
        xi_d = np.array([front + d, 0.0])
        com = np.array([*(xi_d - vel[:2] / OMEGA), 0.8])
        c, v = bounded_com_target(com, vel, OMEGA, _soles(FEET, 0.8))
        forces.append(kp * c[0] + kd * v[0])
        bounded.append(c is not com)
    assert not bounded[0] and bounded[-1]
    assert np.max(np.abs(np.diff(forces))) < 0.1  # per 0.1 mm of ξ_d [N/kg]
    far = np.array([*(np.array([front + 0.2, 0.0]) - vel[:2] / OMEGA), 0.8])
    assert bounded_com_target(far, vel, OMEGA, _soles(FEET, 0.8))[1][0] == 0.0


def test_a_gait_margin_lets_the_capture_point_run_that_far_ahead_and_no_further():
    """His gait's double stance (MotionConfig.gait_capture_step_s): the bound is the polygon grown by the margin."""
    com, vel = np.array([0.2, 0.03, 0.8]), np.array([0.8, 0.1, 0.0])
    outside = _outside(_xi(com, vel), FEET, 0.8)
    assert outside > 0.3
    out_com, out_vel = bounded_com_target(com, vel, OMEGA, _soles(FEET, 0.8), margin_m=0.15)
    xi = _xi(out_com, out_vel)
    assert _outside(xi, FEET, 0.8) == pytest.approx(0.15, abs=1e-9)
    unbounded, _ = bounded_com_target(com, vel, OMEGA, _soles(FEET, 0.8))  # the margin's point is on the same line
    edge = _xi(unbounded, np.zeros(3))
    direction = (_xi(com, vel) - edge) / np.linalg.norm(_xi(com, vel) - edge)
    assert xi - edge == pytest.approx(0.15 * direction, abs=1e-9)
    # within the margin the target is left as it is
    near = np.array([*(edge + 0.1 * direction - vel[:2] / OMEGA), 0.8])
    kept_com, kept_vel = bounded_com_target(near, vel, OMEGA, _soles(FEET, 0.8), margin_m=0.15)
    assert kept_com is near and kept_vel is vel


def test_the_gait_margin_is_what_a_step_then_catches_within_reach():
    """ξ(T) = p + (ξ - p) e^(ω T): a capture point the margin out now is the reach out when the step lands."""
    margin = gait_capture_margin_m(0.6, OMEGA, 0.3)
    assert margin * np.exp(OMEGA * 0.3) == pytest.approx(0.6)
    assert gait_capture_margin_m(0.6, OMEGA, 0.4) < margin  # a later step catches less
    with pytest.raises(ConfigError):
        MotionConfig(gait_capture_step_s=0.0)


def test_on_one_foot_the_bound_is_that_sole():
    stance = FEET[:1]
    com, vel = np.array([0.0, 0.0, 0.8]), np.array([0.0, -0.4, 0.0])  # drifting off the left sole, inwards
    out_com, out_vel = bounded_com_target(com, vel, OMEGA, _soles(stance, 0.8))
    assert _outside(_xi(out_com, out_vel), stance, 0.8) == pytest.approx(0.0, abs=1e-12)
    assert out_com[1] > 0.05  # over the left sole, not between the feet


def test_the_plain_float_geometry_is_the_sole_modules():
    """The per-tick polygon tests on plain floats give the support polygon, distance and nearest point of
    model/sole.py's numpy versions (to rounding), for tilted, turned feet and points inside and out."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        feet = []
        for side in (1.0, -1.0):
            axis = rng.normal(size=3)
            angle = rng.uniform(-0.4, 0.4)
            q = np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis / np.linalg.norm(axis))])
            feet.append((np.array([rng.uniform(-0.3, 0.3), side * rng.uniform(0.05, 0.2), ANKLE_HEIGHT_M]), q))
        share = rng.uniform(0.5, 1.0)
        points = np.vstack([sole_corners_world(a, q, sole_corners_in_foot(share))[:, :2] for a, q in feet])
        polygon = convex_hull_points([p for sole in _soles(feet, share) for p in sole])
        assert np.array(polygon) == pytest.approx(convex_hull_xy(points), abs=1e-12)
        point = rng.uniform(-0.5, 0.5, size=2)
        distance, nearest = outside_distance_points((float(point[0]), float(point[1])), polygon)
        expected, expected_nearest = outside_distance_m(point, convex_hull_xy(points))
        assert distance == pytest.approx(expected, abs=1e-12)
        assert np.array(nearest) == pytest.approx(expected_nearest, abs=1e-12)


def test_the_share_is_checked():
    with pytest.raises(ConfigError):
        MotionConfig(capture_bound_sole_share=1.2)


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_a_lunge_the_character_cannot_stop_from_is_not_asked_for():
    """The built-in punch (seed 1): the operator lunges and punches. Without the bound the character's COM target
    leans past its feet in double stance, it runs forward into the operator's step and falls (measured: 3.3 s); with
    it the punch holds for 12 s. And wherever the character stood on both feet, the target it was given had its
    capture point within its soles."""
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    def run(motion: MotionConfig):
        opened = open_source("builtin:punch", seed=1, duration_s=12.0)
        # Traced before a recovery step's due landing weighed more than its swing: with it the unbounded run holds too
        cfg = SessionConfig(duration_s=12.0, seed=1, operator=OperatorConfig(), motion=motion,
                            control=TRACED_BEFORE_LANDING_WEIGHT)
        session = Session(cfg, opened.source)
        worst = [-np.inf]

        def on_tick(state, ref):
            if ref.character_stance.name == "DS" and motion.capture_bound_sole_share > 0.0:
                _, omega = capture_point(session.mass.com(state), session.mass.com_velocity(state), 9.8)
                xi = ref.com_world[:2] + ref.com_vel_world[:2] / omega
                feet = [(state.link_origin_world[k], state.link_quat_wxyz[k]) for k in (5, 11)]
                worst[0] = max(worst[0], _outside(xi, feet, 1.0))

        session.on_tick = on_tick
        result = session.run()
        opened.source.close()
        return result, worst[0]

    # Traced before the step back of MotionConfig.recovery_step_behind_cos: with it, the lunge's recoil on this seed
    # ends in a step back and a fall at 3.3 s (the suite's punch completes 6 of 8 seeds with it, 8 without); so does
    # the step of MotionConfig.recovery_ds_on_reach_limit, which came after it (the suite's punch is the same).
    # Both runs also before a recovery step's landing on a corner (MotionConfig.recovery_landing_gap_m): with it the
    # unbounded run holds too. And both with the swing aimed at the operator's swing foot's present offset
    # (MotionConfig.swing_landing "his_foot_now"), as it was then.
    bounded, worst = run(MotionConfig(recovery_step_behind_cos=None, recovery_ds_on_reach_limit=False,
                                      recovery_landing_gap_m=None, swing_landing="his_foot_now"))
    assert not bounded.fell
    assert worst <= 0.0
    # Traced with the feet's twist left where it was: with their yaw controlled (MotionConfig.foot_yaw_control) the
    # punch holds without the bound too; so it does with the double stance's reach rule, off in both runs.
    unbounded, _ = run(MotionConfig(capture_bound_sole_share=0.0, foot_yaw_control=False,
                                    recovery_ds_on_reach_limit=False, recovery_landing_gap_m=None,
                                    swing_landing="his_foot_now"))
    assert unbounded.fell and unbounded.fall_time_s < 6.0


def test_a_capture_point_in_the_landing_catch_region_is_caught_by_the_landing_when_the_foot_lands():
    """ξ̇ = ω (ξ - p): from a point of the region, a centre of pressure p held within the stance sole brings ξ within
    the landing's sole (the stance sole moved by the landing's offset) when the foot lands; from a point beyond the
    region, no corner of the stance sole does. A long remaining time draws the region onto the stance sole."""
    rng = np.random.default_rng(3)
    stance = sole_points_xy(np.array([0.1, -0.09, ANKLE_HEIGHT_M]), IDENTITY, sole_corner_points(0.8))
    for _ in range(50):
        offset = (float(rng.uniform(-0.1, 0.5)), float(rng.uniform(0.1, 0.35)))
        k = float(np.exp(-OMEGA * rng.uniform(0.0, 0.6)))
        region_pts = landing_catch_region(stance, offset, k)
        region = convex_hull_points(region_pts)
        landing = convex_hull_points([(x + offset[0], y + offset[1]) for x, y in stance])
        for i in rng.integers(0, len(region_pts), size=5):  # a corner (1 - k) p + k q, p the stance corner held
            xi, p = np.array(region_pts[i]), np.array(stance[i // len(stance)])
            assert outside_distance_points(tuple(p + (xi - p) / k), landing)[0] <= 1e-9
        beyond = np.array(region).mean(axis=0) + np.array([0.0, 0.3])
        if outside_distance_points(tuple(beyond), region)[0] > 1e-3:
            assert all(outside_distance_points(tuple(np.array(p) + (beyond - np.array(p)) / k), landing)[0] > 0.0
                       for p in stance)
    far = convex_hull_points(landing_catch_region(stance, (0.4, 0.2), float(np.exp(-OMEGA * 5.0))))
    assert np.allclose(sorted(far), sorted(convex_hull_points(stance)), atol=1e-6)
    assert np.allclose(sorted(convex_hull_points(landing_catch_region(stance, (0.4, 0.2), 1.0))),
                       sorted((x + 0.4, y + 0.2) for x, y in stance))


ZOMBIE = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "deepmimic" / "humanoid3d_zombie_walk.txt"


@pytest.mark.lowered_takeover
@pytest.mark.pelvis_joint
@pytest.mark.skipif(not ZOMBIE.exists(), reason="../shared/mocap/deepmimic/humanoid3d_zombie_walk.txt is not available")
@pytest.mark.in_place
def test_a_long_single_stance_keeps_the_capture_point_where_the_landing_catches_it_when_opted_in():
    """The zombie walk (seed 0): its operator holds each single stance about 0.8 s with his COM 0.13-0.20 m (scaled)
    inwards of his stance ankle. The character's COM target follows it there, its COM falls inwards over the stance
    foot faster than the swing (held to his timing) lands, and it falls at 5.75 s. With the single stance's bound
    across the heading (MotionConfig.landing_capture_bound "sideways") the target's capture point stays where the
    landing catches it, and the walk holds through its 12 s. (Traced with the reach rule predicting for now once
    his usual swing time is past, ``recovery_overdue_swing_horizon`` off: with it on, the default walk of seed 0
    stands too; and before a recovery step's timing adapted to its reach, ``recovery_swing_min_s`` None, and before a
    lift-off onto a sole the capture point has passed waited however long, ``liftoff_behind_waits`` off: with either,
    the walk stands too.)"""
    from conftest import suite_run

    spec = f"deepmimic:{ZOMBIE}"
    then = {"recovery_overdue_swing_horizon": False, "recovery_swing_min_s": None, "liftoff_behind_waits": False,
            "swing_landing_within_reach": False}  # and before the pelvis target came down as his swing went
    off = suite_run(spec, 0, MotionConfig(**then), TRACED_DIFFERENCED)
    sideways = suite_run(spec, 0, MotionConfig(landing_capture_bound="sideways", **then), TRACED_DIFFERENCED)
    assert off.fell and off.fall_time_s < 6.0
    assert not sideways.fell


def test_the_landing_bound_is_checked():
    with pytest.raises(ConfigError):
        MotionConfig(landing_capture_bound="forwards")

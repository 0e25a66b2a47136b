"""The balance controller's building blocks, each against a known answer, and the free character standing."""

import numpy as np
import pytest
from conftest import random_pose

from stylesync import rotations as rot
from stylesync.config import (
    ControlConfig,
    JacobianTransposeConfig,
    MotionConfig,
    OperatorConfig,
    SessionConfig,
    WholeBodyConfig,
    WorldConfig,
)
from stylesync.control.gravity_compensation import LEG_JOINTS, gravity_torques
from stylesync.control.jacobian_transpose import JointFrames
from stylesync.control.pid import joint_error
from stylesync.control.stable_pd import (
    flatten_joint_values,
    implicit_gain,
    unflatten_joint_values,
)
from stylesync.control.support import limit_ankle_moment, support_point
from stylesync.model.character import N_JOINT_DOFS, ROOT_DOFS, STANDING_ROOT_HEIGHT_M
from stylesync.model.character_model import CharacterModel
from stylesync.session import Session
from stylesync.sim.factory import make_backend
from stylesync.sources.builtin_operator import builtin_operator


def test_implicit_gain_matches_the_scalar_stable_pd():
    # One DOF of inertia m: the implicit PD force is r m / (m + kd dt + kp dt^2).
    m, kp, kd, dt = 0.002, 60.0, 2.0, 1 / 600
    d = kd * dt + kp * dt * dt
    g = implicit_gain(np.array([[m]]), np.array([[d]]))
    assert g[0, 0] == pytest.approx(m / (m + d), rel=1e-12)


def test_flatten_round_trip():
    values = np.random.default_rng(0).normal(size=(12, 3))
    back = unflatten_joint_values(flatten_joint_values(values))
    assert flatten_joint_values(back) == pytest.approx(flatten_joint_values(values))
    assert len(flatten_joint_values(values)) == N_JOINT_DOFS


def test_symmetric_double_stance_needs_no_sideways_hip_or_ankle_torque():
    b = make_backend(WorldConfig(), 600.0)
    b.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M]), rot.IDENTITY_WXYZ)
    s = b.read_state(0.0)
    mass = b.mass_properties().link_mass_kg
    ankles = {side: s.link_origin_world[s.link(f"{side}_ankle")] for side in ("left", "right")}
    tau = gravity_torques(s, JointFrames(s), mass, 9.8, {"left": 0.5, "right": 0.5}, ankles)
    b.close()
    for side in ("left", "right"):
        hip, _, ankle = LEG_JOINTS[side]
        # model x is the lateral (roll) axis of hips and ankles at rest
        assert abs(tau[hip, 0]) < 0.5 and abs(tau[ankle, 0]) < 0.5


def test_support_points_balance_the_com():
    ankles = {"left": np.array([0.0, 0.1, 0.07]), "right": np.array([0.2, -0.1, 0.07])}
    w = {"left": 0.3, "right": 0.7}
    com = np.array([0.18, 0.0, 0.9])
    p = support_point(com, ankles, w)
    centre = w["left"] * p["left"] + w["right"] * p["right"]
    assert centre[:2] == pytest.approx(com[:2])


def test_ankle_moment_is_limited_to_the_sole():
    ankle = np.array([0.0, 0.0, 0.07])
    f = 441.0
    small = np.array([-2.0, 5.0, 0.0])  # centre of pressure 1.1 cm ahead, 0.5 cm to the left: on the sole
    assert limit_ankle_moment(small, ankle, 0.0, f, 0.9) == pytest.approx(small)
    big = np.array([0.0, 100.0, 0.0])  # 23 cm ahead of the ankle: beyond the toes
    limited = limit_ankle_moment(big, ankle, 0.0, f, 0.9)
    toe = 0.045 + 0.8 * 0.177 / 2
    assert limited[1] == pytest.approx(toe * f)
    twist = limit_ankle_moment(np.array([0.0, 0.0, 50.0]), ankle, 0.0, f, 0.9)
    assert twist[2] == pytest.approx(0.9 * f * 0.03)


def test_table3_gains_stay_stable_on_a_root_fixed_character():
    # Table 3's gains without the implicit evaluation diverge at 600 Hz on the feet; with it they track.
    from stylesync.control.pid import JointPid
    from stylesync.model.state import Torques

    b = make_backend(WorldConfig(), 600.0, fixed_root=True)
    b.reset(np.array([0.0, 0.0, 1.5]), rot.IDENTITY_WXYZ)
    target = random_pose(5, hinge_rad=0.5)
    pid = JointPid(JacobianTransposeConfig(), 1 / 600)
    dt = 1 / 600
    d = np.zeros((ROOT_DOFS + N_JOINT_DOFS,) * 2)
    j = np.arange(ROOT_DOFS, ROOT_DOFS + N_JOINT_DOFS)
    d[j, j] = flatten_joint_values(pid.kd * dt + pid.kp * dt * dt)
    model = CharacterModel(b.body_description(), 9.8)
    joints = slice(ROOT_DOFS, None)  # the root is welded: the joints' block of M
    for i in range(1200):
        if i % 4 == 0:
            model.update(b.read_state(0.0))
            g = implicit_gain(model.mass_matrix[joints, joints], d[joints, joints])
        fb = b.read_joint_feedback()
        r = pid(fb.joint_pos, fb.joint_vel, target, np.zeros((12, 3)), predict_dt_s=dt)
        b.apply_torques(Torques(unflatten_joint_values(g @ flatten_joint_values(r))))
        b.step()
    err = np.degrees(np.linalg.norm(joint_error(b.read_state(2.0).joint_pos, target), axis=1))
    vel = b.read_state(2.0).joint_vel
    b.close()
    assert np.abs(vel).max() < 0.5  # settled, no oscillation
    assert err.max() < 15.0  # PD without gravity compensation: a steady sag under gravity, bounded


def _standing_run(duration_s: float, **options):
    """COM (n, 2) and ankle (n, 4) horizontal positions after the first second of a standing run."""
    cfg = SessionConfig(duration_s=duration_s, operator=OperatorConfig(clip="stand"), **options)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    result = Session(cfg, source).run()
    assert not result.fell
    t = result.log.array("t")
    com = np.stack([result.log.array("com_x"), result.log.array("com_y")], axis=1)[t >= 1.0]
    feet = np.stack([result.log.array(k) for k in ("al_x", "al_y", "ar_x", "ar_y")], axis=1)[t >= 1.0]
    return com, feet


@pytest.mark.parametrize("seed", [0, 3])
def test_free_character_stands_60_s_within_2_cm_with_a_standing_operator(seed):
    # The acceptance figure with the default configuration (measured: 1.39 and 0.60 cm; seeds 0-7 at most 1.39 cm).
    com, _ = _standing_run(60.0, seed=seed)
    assert np.linalg.norm(com - com[0], axis=1).max() < 0.02


def test_the_standing_time_constant_is_validated_and_in_place_keeps_none():
    from stylesync.config import ConfigError, in_place

    assert MotionConfig().reference_follows_standing_s == 0.0
    assert in_place(SessionConfig()).motion.reference_follows_standing_s is None
    with pytest.raises(ConfigError, match="reference_follows_standing_s"):
        MotionConfig(reference_follows_standing_s=-0.1)


@pytest.mark.pelvis_joint
def test_targets_that_trail_the_settling_feet_leave_a_stance_that_creeps():
    # With the walking time constant while he stands (MotionConfig.reference_follows_standing_s None), the targets
    # trail the anchored ones by up to 1 cm while the feet settle in the first second, and on sensor seed 3 the stance
    # they leave creeps over the ground at about 1 mm/s (measured: 4.48 cm in 60 s; with the anchored targets from
    # the first second on instead of the start, 4.44 cm).
    com, feet = _standing_run(60.0, seed=3, motion=MotionConfig(reference_follows_standing_s=None))
    assert np.linalg.norm(com - com[0], axis=1).max() > 0.03
    assert np.abs(feet[-1] - feet[0]).max() > 0.03  # the soles, not the body over them


@pytest.mark.pelvis_joint
@pytest.mark.in_place
def test_the_walk_in_place_over_sensor_noise_seeds_mostly_completes_and_follows_the_operators_steps():
    # In place (config.in_place: the defaults before the character followed his path by its landings; by default every
    # run takes steps of its own, below). The walk is chaotic (a change in the 15th digit changes which seeds fall), so
    # it is judged over 12 sensor-noise seeds rather than one. Measured over 48 seeds: 44 to 47 complete 12 s, depending
    # on rounding (before the landing fix and the capture-point COM gains, 4 of 24 completed 10 s). At a completion rate
    # of 0.9, fewer than 8 of 12 complete with a probability below 1 %; at the former 0.17, 8 or more with one of 0.02
    # %. Every run that completes takes >= 80 % of the operator's steps and follows his state transitions within 0.172 s
    # (the paper's figure), but one: with the supporting legs' posture at 0.1 of its weight, seed 6 has one transition
    # of 13 at 0.188 s (the others of all 12 seeds within 0.097 s); one run is allowed up to 0.2 s. A run the balance
    # saves with a step of its own (MotionConfig.recovery_step_behind_cos: seed 6, which otherwise falls at 5.3 s)
    # follows the operator late there (0.68 s): the delays are judged on the runs without one, at most three (with
    # MotionConfig.recovery_overdue_swing_horizon seeds 7 and 11 take one too, where a swing of the operator's outlasts
    # his usual swing time; all 12 complete, their largest delays 0.105 and 0.113 s).
    from stylesync.metrics.summary import summarize

    fall_times, completed, own_steps = [], [], 0
    for seed in range(12):
        cfg = SessionConfig(duration_s=10.0, seed=seed)
        source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
        session = Session(cfg, source)
        result = session.run()
        fall_times.append(result.fall_time_s if result.fell else 10.0)
        if not result.fell and session.motion.recovery.count:
            own_steps += 1
        elif not result.fell:
            completed.append(summarize(result))
    assert len(completed) + own_steps >= 8 and own_steps <= 3, (fall_times, own_steps)
    for m in completed:
        assert m["operator_steps"] >= 8
        assert m["character_steps"] >= 0.8 * m["operator_steps"]
        assert m["state_transition_delay_s"]["max"] <= 0.2
    assert sum(m["state_transition_delay_s"]["max"] > 0.172 for m in completed) <= 1


def test_the_default_walk_over_sensor_noise_seeds_completes_and_goes_his_way():
    # By default the character follows his path by its landings (docs/decisions.md, "Following his path by step
    # placement, the default"). Measured over 48 seeds (12 s): 48 complete, 0.71 of his way at the median (0.35 in
    # place); its swings are taken over by steps of its own where the capture point would leave a step's reach
    # (every run), and the largest transition delay of a run is 0.169 s at the median (0.075 s in place), above the
    # paper's 0.172 s on 24 of 48 (2 in place). Seed 0, the demo's: 16 of 16 steps, at most 0.068 s.
    from stylesync.metrics.summary import summarize

    out = []
    for seed in range(6):
        cfg = SessionConfig(duration_s=10.0, seed=seed)
        source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
        out.append(summarize(Session(cfg, source).run()))
    assert not any(m["fell"] for m in out)
    assert all(m["character_steps"] >= 0.8 * m["operator_steps"] >= 0.8 * 8 for m in out), out
    assert all(m["path_progress"] > 0.55 for m in out), [m["path_progress"] for m in out]
    assert out[0]["state_transition_delay_s"]["max"] <= 0.172


def test_planted_feet_options_keep_a_standing_character_within_2_cm_for_60_s():
    # The acceptance figure (60 s, COM drift < 2 cm) with friction anchors and the sole contact gap.
    com, feet = _standing_run(60.0, world=WorldConfig(friction_anchor=True),
                              control=ControlConfig(whole_body=WholeBodyConfig(sole_contact_gap_m=0.003)))
    assert np.linalg.norm(com - com[0], axis=1).max() < 0.02
    assert np.abs(feet - feet[0]).max() < 0.01  # planted feet stay planted


def test_torso_hip_gives_the_pelvis_exactly_the_root_torque():
    # Eq. 18 realised as SIMBICON's torso control: the pelvis's joints' feedback torques add up to -τ_r on it.
    from stylesync.control.controller import PELVIS_CHILDREN, BalanceController
    from stylesync.control.crvc import HIP_JOINT
    from stylesync.model.character import LINK_NAMES, Q_WORLD_MODEL
    from stylesync.model.state import JointFeedback, MassProperties

    rng = np.random.default_rng(4)
    backend = make_backend(WorldConfig(), 600.0)
    model = CharacterModel(backend.body_description(), 9.8)
    backend.close()
    jt = JacobianTransposeConfig(stance_hip_torso=True)
    ctl = BalanceController(ControlConfig(jacobian_transpose=jt), model, MassProperties(np.ones(len(LINK_NAMES))),
                            9.8, 1 / 600, 1 / 133)
    ctl._torso_hip = HIP_JOINT["left"]
    ctl._ff = rng.normal(0, 5, (12, 3))
    q = random_pose(9)
    fb = JointFeedback(q, np.zeros((12, 3)), rot.quat_from_rotvec(rng.normal(0, 0.2, 3)), np.zeros(3))
    tau = rng.normal(0, 50, (12, 3))
    tau_r = rng.normal(0, 30, 3)
    tau[ctl._torso_hip] = ctl._torso_hip_torque(fb, tau, tau_r)
    q_pelvis = rot.multiply(fb.root_quat_wxyz, Q_WORLD_MODEL)
    on_pelvis = -sum(rot.matrix_from_quat(rot.multiply(q_pelvis, q[k])) @ (tau[k] - ctl._ff[k])
                     for k in PELVIS_CHILDREN)
    assert np.allclose(on_pelvis, tau_r, atol=1e-9)


def test_a_balance_part_the_controller_cannot_switch_off_is_refused():
    from stylesync.errors import ConfigError

    with pytest.raises(ConfigError, match="balance"):
        ControlConfig(balance="inverse_kinematics")
    with pytest.raises(ConfigError, match="momentum_com_kp"):
        WholeBodyConfig(momentum_com_kp=-1.0)
    with pytest.raises(ConfigError, match="integral_limit"):
        JacobianTransposeConfig(integral_limit_rad_s=0.0)
    ControlConfig(balance="jacobian_transpose",
                  jacobian_transpose=JacobianTransposeConfig(gravity_compensation=False, com_virtual_force=False))


def test_bench_baselines_differ_from_stylesync():
    from stylesync.metrics.bench import CONTROLLERS

    assert CONTROLLERS["plain-pd"][0].balance == "jacobian_transpose"
    assert not CONTROLLERS["plain-pd"][0].jacobian_transpose.gravity_compensation
    assert not CONTROLLERS["no-compensation"][0].lipm_time_sync
    assert CONTROLLERS["stylesync"][0].lipm_time_sync


def test_joint_error_over_many_ticks_matches_tick_by_tick():
    q = np.stack([random_pose(k, hinge_rad=0.1 * k) for k in range(6)])
    q_ref = np.stack([random_pose(10 + k, hinge_rad=0.5) for k in range(6)])
    batched = joint_error(q, q_ref)
    for k in range(6):
        assert np.abs(batched[k] - joint_error(q[k], q_ref[k])).max() < 1e-12


def test_same_input_and_seed_give_the_same_simulation_offline_and_paced():
    # Issue clocks: the run paced to the wall clock and the run as fast as possible are the same simulation, and
    # so are two offline runs (the warm-started force plan carries state from tick to tick, in tick order only).
    def run(realtime: bool) -> dict[str, np.ndarray]:
        cfg = SessionConfig(duration_s=2.5, seed=3, realtime=realtime)
        source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
        log = Session(cfg, source).run().log
        return {k: log.array(k) for k in ("com_x", "com_y", "com_z", "root_z", "char_state", "joint_err_deg")}

    first, second, paced = run(False), run(False), run(True)
    for key, values in first.items():
        assert np.array_equal(values, second[key]), key
        assert np.array_equal(values, paced[key]), key


def test_eq26_is_checked_on_the_operators_motion_and_the_clamp_counted_apart():
    """Eq. 26 reported against what the operator's motion asks of an exactly tracking character; the clamp of the
    applied force (which carries the character's own lag) is counted apart and is not an operator's bound."""
    from stylesync.control.model_compensation import bounded_lipm_sync_force, synchronised_tracking_force_n
    from stylesync.motion.bounds import BoundsMonitor, lipm_force_bound_n
    from stylesync.motion.reference import LipmMap

    m, g, h_h, h_c = 45.0, 9.8, 0.95, 0.75
    limit = lipm_force_bound_n(m, g, h_c)
    # A walk: his COM 0.2 m ahead of his stance ankle, the character 0.1 m behind its own (lagging).
    walk = LipmMap(np.array([0.2, 0.0, 0.0]), h_h, np.array([-0.1, 0.0, 0.0]), h_c)
    assert synchronised_tracking_force_n(walk, m, g) < limit
    b = BoundsMonitor()
    f = bounded_lipm_sync_force(walk, m, g, 1e9, True, b, 0.0)
    assert np.linalg.norm(f) == pytest.approx(limit)  # the applied force is clamped ...
    assert b.counts["lipm_clamped"] == 1 and b.counts["lipm_force"] == 0  # ... but he asked for nothing beyond
    assert b.summary(600.0) is None
    # A lunge far beyond his stance foot asks more than the character's foot can pass.
    lunge = LipmMap(np.array([0.8, 0.0, 0.0]), h_h, np.array([0.8 * h_c / h_h, 0.0, 0.0]), h_c)
    assert synchronised_tracking_force_n(lunge, m, g) > limit
    bounded_lipm_sync_force(lunge, m, g, 1e9, True, b, 1.5)
    assert b.counts["lipm_force"] == 1
    line = b.summary(600.0)
    assert line is not None and "lipm_force" in line and "t=1.50 s" in line
    demand = synchronised_tracking_force_n(lunge, m, g)
    assert f"asks |f_cro| {demand:.0f} N > {limit:.0f} N (Eq. 26)" in line  # the detail, formatted when exceeded


def test_the_built_in_walk_exceeds_no_movement_bound_and_logs_no_warning(caplog):
    import logging

    from stylesync.config import SessionConfig
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    opened = open_source("builtin:walk", seed=0, duration_s=6.0)
    with caplog.at_level(logging.WARNING):
        result = Session(SessionConfig(duration_s=6.0, seed=0), opened.source).run()
    assert not result.fell
    assert result.bound_counts["lipm_force"] == 0 and result.bound_counts["step_length"] == 0
    assert result.bound_counts["lipm_clamped"] > 0  # the controller does work at its limit meanwhile
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def _record_feet_yaw_off_pelvis_deg(session: Session, pressing_only: bool) -> list[float]:
    """The list that ``session``'s control ticks fill with each foot's yaw from the pelvis's [deg] (with
    ``pressing_only``, the feet that press the ground)."""
    from stylesync.model.character import LINK_NAMES, Q_WORLD_MODEL

    up = np.array([0.0, 0.0, 1.0])
    ankle = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
    off: list[float] = []

    def on_tick(state, ref) -> None:
        pelvis = rot.twist_angle(rot.multiply(state.root_quat_wxyz, rot.conjugate(Q_WORLD_MODEL)), up)
        for side, pressing in state.feet_pressing().items():
            if pressing or not pressing_only:
                d = rot.twist_angle(state.link_quat_wxyz[ankle[side]], up) - pelvis
                off.append(abs(np.degrees((d + np.pi) % (2 * np.pi) - np.pi)))

    session.on_tick = on_tick
    return off


def _planted_foot_yaw_off_deg(motion: MotionConfig, seconds: float) -> np.ndarray:
    """Over a built-in walk (seed 0): each pressing foot's yaw from the pelvis's, per control tick [deg]."""
    from stylesync.sources.registry import open_source

    opened = open_source("builtin:walk", seed=0, duration_s=seconds)
    session = Session(SessionConfig(duration_s=seconds, seed=0, motion=motion), opened.source)
    off = _record_feet_yaw_off_pelvis_deg(session, pressing_only=True)
    assert not session.run().fell
    opened.source.close()
    return np.array(off)


def test_the_feet_land_and_stay_along_the_body_not_turned_on_their_ankles():
    """The ankle is a ball joint: a twist about the shank left to itself drifted from step to step, and on the
    built-in walk a quarter of the planted ticks had a foot more than 60° from the pelvis (measured: 16 % beyond
    90°). With the swing foot turned to its yaw and an unloaded planted foot keeping its own, none is beyond 45°."""
    controlled = _planted_foot_yaw_off_deg(MotionConfig(), 8.0)
    assert controlled.size > 1000 and controlled.max() < 45.0
    drifting = _planted_foot_yaw_off_deg(MotionConfig(foot_yaw_control=False), 8.0)
    assert np.mean(drifting > 60.0) > 0.1


@pytest.mark.pelvis_joint
@pytest.mark.parametrize("placed, feet_max_deg", [(True, 60.0), (False, 90.0)])
def test_the_walk_turns_with_an_operator_who_walks_a_circle(placed, feet_max_deg):
    # The built-in walk bent into a turn at 0.6 rad/s after the lead-in (a circle of about 1.7 m radius; 0.6 * 7 s
    # is 240 degrees). Measured in place (config.in_place; benchmarks/turning_walk.py, seeds 0-1, 12 s, up to 1.0
    # rad/s): no fall, every step, the character's facing within 17 degrees of his; a character that did not turn
    # would be 240 off. Its feet turn with it: at 0.6 rad/s each foot's heading is within 24-27 degrees of the
    # pelvis's at the 95th percentile, 45 at most (8 s, seeds 0-3: 44-56). By default, following his path by its
    # landings, the feet come further off the pelvis's heading on some seeds (8 s, seeds 0-3: 73, 43, 44, 82).
    from stylesync.config import in_place
    from stylesync.metrics.imitation import facing_error_deg, facing_rad
    from stylesync.metrics.summary import summarize

    cfg = SessionConfig(duration_s=8.0, seed=0, operator=OperatorConfig(turn_rate_rad_s=0.6))
    if placed:
        cfg = in_place(cfg)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    # Each foot's heading against the pelvis's: the feet turn with the body by its steps (a turret on planted feet,
    # its legs twisted about their own axes, would reach 180)
    feet_from_pelvis_deg = _record_feet_yaw_off_pelvis_deg(session, pressing_only=False)
    result = session.run()
    assert not result.fell
    assert max(feet_from_pelvis_deg) < feet_max_deg
    m = summarize(result)
    assert m["character_steps"] >= m["operator_steps"] - 1 >= 8
    his = np.degrees(np.unwrap(facing_rad(np.asarray(result.log.columns["op_joints"]))))
    assert his[-1] - his[0] == pytest.approx(np.degrees(0.6 * 7.0), abs=25.0)  # he turned
    t = result.log.array("t")
    err = facing_error_deg(np.asarray(result.log.columns["ch_joints"]), np.asarray(result.log.columns["op_joints"]))
    assert np.abs(err[t >= 1.0]).max() < 25.0

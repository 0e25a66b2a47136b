import dataclasses
import inspect
import time

import numpy as np
import pytest

from stylesync import rotations as rot
from stylesync.config import (
    IN_PLACE_MOTION,
    IN_PLACE_OPERATOR,
    IN_PLACE_WHOLE_BODY,
    PELVIS_JOINT_MOTION,
    ControlConfig,
    MotionConfig,
    OperatorConfig,
    WholeBodyConfig,
    WorldConfig,
)
from stylesync.model.character import JOINTS, STANDING_ROOT_HEIGHT_M, JointKind

# Scenarios traced before a recovery step's due landing weighed more than its swing (WholeBodyConfig.
# recovery_foot_landing_weight) and before the joints' no-load speed (joint_speed_limit_rad_s): with them, the
# contrast runs of some of them no longer fall; before the bound on the push of the character's own steps
# (own_step_push_bound); before a recovery foot followed its swing profile's velocity (recovery_foot_target_rate);
# before the pelvis tracked a jump's push (pelvis_rate_share); and before a double stance's unweighted foot was
# pressed down (press_double_stance_feet). All of them were traced in place (config.in_place; the tests that run them
# carry the in_place marker): the push of the character's own steps bounded only while he stands.
TRACED_BEFORE_LANDING_WEIGHT = ControlConfig(whole_body=WholeBodyConfig(
    recovery_foot_landing_weight=WholeBodyConfig().recovery_foot_task_weight, joint_speed_limit_rad_s=None,
    own_step_push_bound="off", recovery_foot_target_rate="differenced", pelvis_rate_share=0.0,
    press_double_stance_feet=False))
# Scenarios traced before a recovery foot followed its swing profile's velocity: its target's velocity was differenced
# from tick to tick (WholeBodyConfig.recovery_foot_target_rate), and their runs' own steps land otherwise without it;
# before the pelvis tracked a jump's push (pelvis_rate_share 0: the regulator alone); and before a double stance's
# unweighted foot was pressed down (press_double_stance_feet).
TRACED_DIFFERENCED = ControlConfig(whole_body=WholeBodyConfig(recovery_foot_target_rate="differenced",
                                                              pelvis_rate_share=0.0, press_double_stance_feet=False,
                                                              own_step_push_bound="he_stands"))
# Scenarios traced before a double stance's foot off the ground was pressed down whatever its stance weight
# (WholeBodyConfig.press_double_stance_feet): their runs part from the traced ones where such a foot rose. (Traced
# before the standing soles' load bound too: standing_sole_min_load_share 0.)
TRACED_BEFORE_PRESS = ControlConfig(whole_body=WholeBodyConfig(press_double_stance_feet=False,
                                                               own_step_push_bound="he_stands",
                                                               standing_sole_min_load_share=0.0))


# Scenarios traced with his skeleton's pelvis joint as his pelvis and the pelvis target at his (scaled), the
# defaults before 2026-12-06, not through his hip joints with the target below his (config.PELVIS_JOINT_MOTION;
# docs/decisions.md, "His pelvis at his hip joints"): the tests that run them carry the pelvis_joint marker (those
# with the in_place marker, traced before either, have them too), so that they stay as traced whatever the defaults.
# Scenarios traced while every swing the balance took over was lowered from where its foot was, on the ground or not
# (MotionConfig.recovery_takeover_low_foot_m None, the default before 2026-12-06; docs/decisions.md, "A swing taken
# over on the ground"): the tests that run them carry the lowered_takeover marker.
# Scenarios traced while the operator's heading was his pelvis's forward axis's in every pose (rotations.yaw_from_quat,
# before 2026-12-06; docs/decisions.md, "The operator's heading where his trunk bends over"): the tests that run them
# carry the forward_heading marker.
# Scenarios traced while a sole his weight leaves where he stands could be planned unloaded
# (WholeBodyConfig.standing_sole_min_load_share 0, the default before 2026-12-07; docs/decisions.md, "A sole unloaded
# where he stands"): the tests that run them carry the unloaded_standing_sole marker.
# Scenarios traced while a recording that starts standing started with its first two frames' velocity and its feet
# where his are from his pelvis (MotionConfig.standing_start_at_rest False, standing_start_sole_share None, the defaults
# before 2026-12-07; docs/decisions.md, "A standing start over the toes"): the tests that run them carry the
# moving_standing_start marker.


def pytest_configure(config):
    config.addinivalue_line("markers", "in_place: a scenario traced with the settings before the character followed "
                                       "its operator's path by default (config.in_place): every MotionConfig, "
                                       "WholeBodyConfig and OperatorConfig made during the test defaults to them")
    config.addinivalue_line("markers", "pelvis_joint: a scenario traced with his pelvis joint as his pelvis and the "
                                       "pelvis target at his (PELVIS_JOINT_MOTION): every MotionConfig made during the "
                                       "test defaults to them")
    config.addinivalue_line("markers", "lowered_takeover: a scenario traced while every taken-over swing was lowered "
                                       "from where its foot was (recovery_takeover_low_foot_m None): every "
                                       "MotionConfig made during the test defaults to that")
    config.addinivalue_line("markers", "forward_heading: a scenario traced while the operator's heading was his "
                                       "pelvis's forward axis's in every pose (rotations.yaw_from_quat)")
    config.addinivalue_line("markers", "unloaded_standing_sole: a scenario traced while a standing sole could be "
                                       "planned unloaded: every WholeBodyConfig made during the test defaults to "
                                       "standing_sole_min_load_share 0")
    config.addinivalue_line("markers", "moving_standing_start: a scenario traced while a recording started standing "
                                       "with its first frames' velocity and its feet where his are: every "
                                       "MotionConfig made during the test defaults to that")


def _set_defaults(monkeypatch, cls: type, values: dict) -> None:
    """For the test's duration, the defaults of the dataclass ``cls`` for the keys of ``values`` are those values."""
    init = cls.__init__
    names = [n for n, p in inspect.signature(init).parameters.items()
             if n != "self" and p.default is not inspect.Parameter.empty]
    assert len(names) == len(init.__defaults__) and set(values) <= set(names)
    monkeypatch.setattr(init, "__defaults__",
                        tuple(values.get(n, d) for n, d in zip(names, init.__defaults__, strict=True)))


@pytest.fixture(autouse=True)
def _traced_defaults(request, monkeypatch):
    """Under the ``in_place`` marker, the defaults of MotionConfig, WholeBodyConfig and OperatorConfig are those of
    config.in_place (and PELVIS_JOINT_MOTION's) for the test's duration; under ``pelvis_joint``, MotionConfig's are
    PELVIS_JOINT_MOTION's too; under ``lowered_takeover``, its recovery_takeover_low_foot_m is None (what a test sets
    explicitly stays as it sets it); under ``forward_heading``, the operator's heading is rotations.yaw_from_quat; under
    ``unloaded_standing_sole``, WholeBodyConfig's standing_sole_min_load_share is 0; under ``moving_standing_start``,
    MotionConfig's standing_start_at_rest is False and standing_start_sole_share None."""
    motion: dict = {}
    if request.node.get_closest_marker("pelvis_joint") is not None:
        motion.update(PELVIS_JOINT_MOTION)
    if request.node.get_closest_marker("in_place") is not None:
        motion.update(PELVIS_JOINT_MOTION)
        motion.update(IN_PLACE_MOTION)
        _set_defaults(monkeypatch, WholeBodyConfig, IN_PLACE_WHOLE_BODY)
        _set_defaults(monkeypatch, OperatorConfig, IN_PLACE_OPERATOR)
    if request.node.get_closest_marker("lowered_takeover") is not None:
        motion["recovery_takeover_low_foot_m"] = None
    if request.node.get_closest_marker("moving_standing_start") is not None:
        motion.update(standing_start_at_rest=False, standing_start_sole_share=None)
    if motion:
        _set_defaults(monkeypatch, MotionConfig, motion)
    if request.node.get_closest_marker("unloaded_standing_sole") is not None:
        _set_defaults(monkeypatch, WholeBodyConfig, {"standing_sole_min_load_share": 0.0})
    if request.node.get_closest_marker("forward_heading") is not None:
        # (the operator side's worker is forked from this process: it computes the heading so too)
        monkeypatch.setattr(rot, "heading_from_quat", rot.yaw_from_quat)
        monkeypatch.setattr(rot, "batch_heading_from_quat", _forward_headings)


def _forward_headings(q: np.ndarray) -> np.ndarray:
    """rotations.yaw_from_quat of each row of ``q`` (n, 4) [rad]."""
    return np.array([rot.yaw_from_quat(row) for row in np.asarray(q, dtype=float)])


def _standing(root_quat_wxyz: np.ndarray):
    """(backend, model): the character put on flat ground with the root orientation ``root_quat_wxyz`` and left
    0.5 s at 600 Hz, its model updated there; the backend is closed when the generator ends."""
    from stylesync.model.character_model import CharacterModel
    from stylesync.sim.pybullet_backend import PyBulletBackend

    backend = PyBulletBackend(WorldConfig(), 600.0)
    backend.reset(np.array([0.0, 0.0, STANDING_ROOT_HEIGHT_M]), root_quat_wxyz)
    for _ in range(300):
        backend.step()
    model = CharacterModel(backend.body_description(), 9.8)
    model.update(backend.read_state(0.5))
    yield backend, model
    backend.close()


@pytest.fixture(scope="module")
def standing():
    """(backend, model): the character standing on flat ground after 0.5 s at 600 Hz, its model updated there (one
    per test module)."""
    yield from _standing(rot.IDENTITY_WXYZ)


@pytest.fixture(scope="module")
def turned_model():
    """The model of the character put on flat ground turned by 0.6 rad about the vertical and left 0.5 s at 600 Hz
    (sinking onto its feet; one per test module)."""
    for _, model in _standing(rot.quat_from_axis_angle(np.array([0, 0, 1.0]), 0.6)):
        yield model


def random_pose(seed: int, ball_sigma_rad: float = 0.3, hinge_rad: float = 0.6) -> np.ndarray:
    """A reproducible joint pose (n_joints, 4): random ball rotations, knees flexed, elbows bent."""
    rng = np.random.default_rng(seed)
    q = np.zeros((len(JOINTS), 4))
    for k, j in enumerate(JOINTS):
        if j.kind is JointKind.BALL:
            q[k] = rot.quat_from_rotvec(rng.normal(0, ball_sigma_rad, 3))
        else:
            q[k, 0] = -hinge_rad if "knee" in j.name else hinge_rad
    return q


def suite_run(spec: str, seed: int, motion: MotionConfig, control: ControlConfig, on_tick=None, watch=None,
              configure=None):
    """One development-suite run of ``spec`` (its configuration and source as the suite opens them) with ``motion``
    and ``control``, and then ``configure(cfg) -> cfg`` if given. ``on_tick(state, ref)`` is called each control
    tick; or ``watch(session)`` returns that callback, for one that reads the session itself."""
    from stylesync.metrics.dev_suite import suite_config
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    opened = open_source(spec, seed=seed, duration_s=12.0)
    cfg, _ = suite_config(spec, opened, seed, 12.0)
    cfg = dataclasses.replace(cfg, motion=motion, control=control)
    session = Session(configure(cfg) if configure is not None else cfg, opened.source)
    if watch is not None:
        on_tick = watch(session)
    if on_tick is not None:
        session.on_tick = on_tick
    result = session.run()
    opened.source.close()
    return result


def wait_frames(source, n: int, timeout_s: float = 1.0) -> int:
    """Waits until a live ``source`` has received ``n`` frames, at most ``timeout_s``; the count it has then."""
    t0 = time.perf_counter()
    while source.frames_received < n and time.perf_counter() - t0 < timeout_s:
        time.sleep(0.001)
    return source.frames_received

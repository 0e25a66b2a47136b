"""Imitation metrics on hand-made trajectories with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from stylesync.metrics import imitation as im


def _walker(n: int = 400, dt: float = 0.01) -> np.ndarray:
    """(n, 3, 3) three joints moving on smooth, different periodic paths."""
    t = np.arange(n) * dt
    pos = np.zeros((n, 3, 3))
    for j, f in enumerate((0.7, 1.3, 2.1)):
        pos[:, j, 0] = np.sin(2 * np.pi * f * t + j)
        pos[:, j, 1] = 0.5 * np.cos(2 * np.pi * 0.9 * f * t)
        pos[:, j, 2] = 1.0 + 0.1 * j
    return pos


def test_a_known_offset_gives_that_mpjpe():
    ref = _walker()
    char = ref + np.array([0.03, 0.04, 0.0])  # 5 cm everywhere
    assert im.mpjpe_mm(char, ref) == pytest.approx(50.0)
    assert im.mpjpe_mm(char, ref, root_relative=True) == pytest.approx(0.0, abs=1e-9)
    bent = ref.copy()
    bent[:, 2] += np.array([0.0, 0.0, 0.06])  # one joint of three off by 6 cm, relative to the root
    assert im.mpjpe_mm(bent, ref, root_relative=True) == pytest.approx(20.0)


def test_a_known_shift_gives_that_lag():
    dt = 0.01
    op = _walker(600, dt).reshape(600, -1)
    for shift in (0, 7, 23):
        char = np.roll(op, shift, axis=0)  # the character repeats the operator `shift` ticks later
        assert im.sync_lag_s(op[50:550], char[50:550], dt) == pytest.approx(shift * dt)
    early = np.roll(op, -12, axis=0)
    assert im.sync_lag_s(op[50:550], early[50:550], dt) == pytest.approx(-0.12)


def test_a_sliding_foot_gives_that_skate():
    n = 101
    feet = np.zeros((n, 2, 3))
    feet[:, 0, 0] = np.linspace(0.0, 0.1, n)  # left foot slides 10 cm over 100 ticks: 1 mm per tick
    contact = np.ones((n, 2), dtype=bool)
    # Two feet in contact, one sliding 1 mm/tick, one still: mean 0.5 mm per foot-tick.
    assert im.foot_skate_mm(feet, contact) == pytest.approx(0.5)
    contact[:, 1] = False  # only the sliding foot counts
    assert im.foot_skate_mm(feet, contact) == pytest.approx(1.0)
    contact[:, 0] = False  # a foot in the air does not skate
    assert im.foot_skate_mm(feet, contact) == 0.0


def test_jitter_of_a_constant_acceleration():
    dt = 0.01
    t = np.arange(200) * dt
    pos = np.zeros((200, 1, 3))
    pos[:, 0, 2] = -0.5 * 9.8 * t**2  # free fall
    assert im.jitter_mps2(pos, dt) == pytest.approx(9.8, rel=1e-6)
    assert im.jitter_mps2(np.zeros((50, 4, 3)), dt) == 0.0


def test_path_progress_of_a_character_that_goes_part_of_the_way_back_or_aside():
    t = np.linspace(0.0, 1.0, 50)[:, None]
    ref = np.hstack([4.0 * t, 3.0 * t, np.full_like(t, 0.9)])  # 5 m along (0.8, 0.6)
    half = ref * [0.5, 0.5, 1.0]
    assert im.path_progress(half, ref) == pytest.approx((0.5, 0.0))
    back = ref * [-0.2, -0.2, 1.0]
    assert im.path_progress(back, ref)[0] == pytest.approx(-0.2)
    aside = np.hstack([-3.0 * t, 4.0 * t, np.full_like(t, 0.9)])  # 5 m square to his line
    progress, sideways = im.path_progress(aside, ref)
    assert progress == pytest.approx(0.0, abs=1e-12) and sideways == pytest.approx(5.0)
    in_place = np.hstack([0.3 * t, 0.0 * t, np.full_like(t, 0.9)])
    assert im.path_progress(ref, in_place) == (None, None)


def test_step_width_across_the_pelvis_whichever_way_it_faces():
    n = len(im.JOINT_PAIRS)
    joint = {o: k for k, o in enumerate(im.OPERATOR_JOINTS)}
    pos = np.zeros((3, n, 3))
    for k, yaw in enumerate((0.0, 0.7, -2.5)):  # facing +x, turned left, turned round to the right
        fwd, left = np.array([np.cos(yaw), np.sin(yaw), 0.0]), np.array([-np.sin(yaw), np.cos(yaw), 0.0])
        pos[k, joint["HIP_LEFT"]], pos[k, joint["HIP_RIGHT"]] = 0.08 * left + [0, 0, 0.8], -0.08 * left + [0, 0, 0.8]
        width = (0.14, 0.0, -0.05)[k]  # apart, in line, crossed
        pos[k, joint["ANKLE_LEFT"]] = 0.3 * fwd + 0.5 * width * left + [0, 0, 0.05]
        pos[k, joint["ANKLE_RIGHT"]] = -0.3 * fwd - 0.5 * width * left + [0, 0, 0.05]
    np.testing.assert_allclose(im.step_widths_m(pos, np.array([0, 1, 2])), [0.14, 0.0, -0.05], atol=1e-12)
    np.testing.assert_allclose(im.step_widths_m(pos, np.array([2])), [-0.05], atol=1e-12)


def test_uhc_termination_and_operator_scaling():
    ref = _walker()
    char = ref.copy()
    char[250:] += np.array([0.0, 0.0, -0.6])  # falls 60 cm at tick 250
    assert im.uhc_fall_index(char, ref) == 250
    assert im.uhc_fall_index(ref, ref) is None
    op = np.zeros((2, 2, 3))
    op[:, 0] = [1.0, 2.0, 1.0]  # pelvis
    op[:, 1] = [1.0, 2.0, 0.0]  # a foot below it
    scaled = im.scale_operator_to_character(op, 0.5, np.array([0.0, 0.0, 0.9]))
    np.testing.assert_allclose(scaled[0, 0], [0.0, 0.0, 0.5])
    np.testing.assert_allclose(scaled[0, 1], [0.0, 0.0, 0.0])


def test_a_termination_is_split_into_the_pelvis_offset_and_the_pose():
    """His pelvis walks along +y at 1 m/s with a leg below it: a character 0.5 m behind him, 0.55 m to his side, 0.6 m
    lower, or with its leg bent 1.2 m out, ends for each of those; where he stands, a pelvis offset is 'in place'."""
    t = np.arange(200) * 0.01
    ref = np.zeros((200, 2, 3))
    ref[:, 0] = np.column_stack([np.zeros(200), t, np.full(200, 0.9)])
    ref[:, 1] = ref[:, 0] - [0.0, 0.0, 0.8]
    cases = {"behind": [0.0, -0.5, 0.0], "ahead": [0.0, 0.5, 0.0], "aside": [0.55, 0.1, 0.0], "height": [0, 0, -0.6]}
    for cause, offset in cases.items():
        split = im.termination_split(t, ref + np.array(offset, dtype=float), ref, 150)
        assert split["cause"] == cause
        assert split["along"] == pytest.approx(offset[1]) and split["across"] == pytest.approx(abs(offset[0]))
        assert split["height"] == pytest.approx(offset[2]) and split["pose"] == pytest.approx(0.0, abs=1e-12)
        assert split["distance"] == pytest.approx(float(np.linalg.norm(offset)))
        assert split["his_mps"] == pytest.approx(1.0) and split["its_mps"] == pytest.approx(1.0)
    bent = ref.copy()
    bent[:, 1, 0] += 1.2
    split = im.termination_split(t, bent, ref, 150)
    assert split["cause"] == "pose" and split["pose"] == pytest.approx(0.6) and split["distance"] == pytest.approx(0.6)
    standing = ref.copy()
    standing[:, :, 1] = 0.0  # he stands where he started
    split = im.termination_split(t, standing + np.array([0.0, -0.5, 0.0]), standing, 150)
    assert split["cause"] == "in place" and split["his_mps"] == pytest.approx(0.0)


def test_mpjpe_before_the_termination_leaves_out_what_follows_it():
    ref = _walker()
    char = ref + np.array([0.12, 0.16, 0.0])  # 20 cm everywhere ...
    char[250:] += np.array([0.0, 0.0, -0.6])  # ... and 60 cm lower from tick 250 on: the termination there
    assert im.uhc_fall_index(char, ref) == 250
    assert im.mpjpe_before_termination_mm(char, ref) == pytest.approx(200.0)
    assert im.mpjpe_mm(char, ref) > 300.0  # the whole run's counts the 150 ticks after it
    assert im.mpjpe_before_termination_mm(char, ref, root_relative=True) == pytest.approx(0.0, abs=1e-9)
    assert im.mpjpe_before_termination_mm(ref + 0.01, ref) == pytest.approx(im.mpjpe_mm(ref + 0.01, ref))
    first = ref + np.array([0.0, 0.0, 0.7])  # beyond the distance from the first tick: that tick alone
    assert im.mpjpe_before_termination_mm(first, ref) == pytest.approx(700.0)


def test_report_holds_metrics_figures_and_versions(tmp_path):
    from stylesync.metrics.report import write_report

    (tmp_path / "metrics.json").write_text('{"fell": false, "mpjpe_global_mm": 123.4, "delay": {"max": 0.1}}')
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    fig.savefig(tmp_path / "fig.png")
    plt.close(fig)
    text = write_report(tmp_path).read_text()
    assert "mpjpe_global_mm" in text and "123.4" in text and "delay.max" in text
    assert "data:image/png;base64," in text and "pybullet" in text


def test_unknown_experiment_and_missing_shared_clips_fail_with_one_line(capsys, tmp_path):
    from stylesync.cli import main
    from stylesync.errors import StylesyncError
    from stylesync.experiments import styles

    with pytest.raises(SystemExit) as e:
        main(["experiment", "nonsense"])
    assert e.value.code == 2
    with pytest.raises(StylesyncError, match="needs .*humanoid3d_stealthy_walk.txt"):
        styles.run(tmp_path / "out", shared=tmp_path / "no-shared")


def test_the_styles_experiment_measures_each_style_s_step_width(tmp_path):
    from stylesync.config import SHARED_DIR
    from stylesync.experiments import styles

    if not (SHARED_DIR / "mocap" / "deepmimic").is_dir():
        pytest.skip("../shared/mocap/deepmimic is not available")
    _, summary = styles.run(tmp_path / "out", duration_s=6.0)
    for style, m in summary["styles"].items():
        # his steps land 0.15-0.45 m apart across his pelvis in all three (scaled); the character's are measured alike
        assert 0.15 < m["operator"]["step_width_m"] < 0.45, style
        assert isinstance(m["character"]["step_width_m"], float), style


def test_transition_delays_count_a_missed_change_and_leave_out_one_the_log_ends_on():
    from stylesync.metrics.summary import transition_delays

    t = np.arange(400) * 0.01  # 4 s
    op = np.ones(400, dtype=int)
    ch = np.ones(400, dtype=int)
    op[50:150] = 0  # the operator lifts a foot at 0.5 s ...
    ch[58:150] = 0  # ... the character 80 ms later
    op[200:] = 2  # at 2.0 s he lifts the other; the character never does (its 1 s window ends before the log)
    op[390:] = 0  # 3.9 s: the log ends 90 ms later, the character not yet following: unknown, left out
    delays = transition_delays(t, op, ch)
    assert delays == pytest.approx([0.08, 0.0, 1.0])

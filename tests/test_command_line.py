"""Bad command lines end with exit 2 and one line naming the option, before anything runs."""

import json
from pathlib import Path

import pytest

from stylesync.cli import main as cli_main


def _exit_code(argv: list[str]) -> int:
    try:
        return cli_main(argv)
    except SystemExit as exc:  # argparse's own exit
        return int(exc.code or 0)


@pytest.mark.parametrize("argv, says", [
    (["run", "--source", "builtin:walk", "--duration", "nan"], "--duration"),
    (["run", "--source", "builtin:walk", "--duration", "inf"], "--duration"),
    (["run", "--source", "builtin:walk", "--duration", "1e9"], "--duration"),
    (["run", "--source", "builtin:walk", "--duration", "-1"], "--duration"),
    (["demo", "--duration", "abc"], "--duration"),
    (["run", "--source", "builtin:walk", "--seed", "-1"], "--seed"),
    (["run", "--source", "builtin:walk", "--viewer-port", "70000"], "--viewer-port"),
    (["run", "--source", "builtin:walk", "--viewer-hz", "0"], "--viewer-hz"),
    (["measure", "--source", "builtin:walk", "--mass", "-5"], "--mass"),
    (["replay", "--speed", "0", "x.jsonl"], "--speed"),
    (["report", "/no/such/folder"], "folder"),
    (["inspect", "/no/such/file.bvh"], "file"),
    (["bench", "--seeds", "0"], "--seeds"),
    (["bench", "--mirror"], "--mirror"),
    (["bench", "--sensor-noise", "2"], "--sensor-noise"),
    (["bench", "--suite", "dev", "--sensor-noise", "-1"], "--sensor-noise"),
    (["run", "--source", "builtin:walk", "--bvh-scale", "-0.01"], "--bvh-scale"),
    (["run", "--source", "vmc://127.0.0.1:99999", "--duration", "0.1"], "VMC port"),
])
def test_bad_values_end_with_one_line(argv, says, capsys):
    assert _exit_code(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err and "Traceback" not in err, err


def test_out_naming_a_file_or_an_export_into_a_file(tmp_path, capsys):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    for argv in (["demo", "--out", str(a_file)], ["demo", "--export-bvh", str(tmp_path)],
                 ["demo", "--out", str(a_file / "below")]):
        assert _exit_code(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and ("--out" in err or "--export-bvh" in err), err


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc, a folder nobody can write into")
def test_out_that_cannot_be_written_even_by_root(tmp_path, capsys):
    """Tried, not read from permission bits: root may write anywhere the bits say, but not into /proc."""
    for argv, option in ((["demo", "--out", "/proc/stylesync-out"], "--out"),
                         (["demo", "--export-bvh", "/proc/stylesync.bvh"], "--export-bvh")):
        assert _exit_code(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and option in err and "Traceback" not in err, err
    # a folder that can be made is made only by the run itself: the check leaves nothing behind
    assert _exit_code(["demo", "--out", str(tmp_path / "new" / "out"), "--duration", "nan"]) == 2
    assert not (tmp_path / "new").exists()


def test_an_export_into_a_missing_folder_creates_it(tmp_path, capsys):
    bvh = tmp_path / "new" / "deeper" / "walk.bvh"
    assert cli_main(["demo", "--duration", "0.2", "--out", str(tmp_path / "out"), "--export-bvh", str(bvh)]) == 0
    assert bvh.is_file() and bvh.read_text().startswith("HIERARCHY")


def test_the_demo_takes_the_start_ramp_and_records_it(tmp_path, capsys):
    import json

    assert cli_main(["demo", "--duration", "0.3", "--start-ramp", "rate", "--out", str(tmp_path / "o")]) == 0
    assert json.loads((tmp_path / "o" / "metrics.json").read_text())["start_ramp"] == "rate"
    assert _exit_code(["demo", "--start-ramp", "slide", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert "--start-ramp" in err and "Traceback" not in err


def test_a_recording_asked_to_run_past_its_end_stops_at_its_end_plus_the_rest(tmp_path, capsys):
    import json
    from pathlib import Path

    cmu = Path(__file__).resolve().parents[2] / "shared" / "mocap" / "cmu" / "02_01.bvh"
    if not cmu.exists():
        pytest.skip("../shared/mocap/cmu/02_01.bvh is not available")
    out = tmp_path / "o"
    # 80 000 s asked for: the frames were made for the whole duration up front (a hang); now cut at 2.85 + 3 s (the
    # run goes on after a fall, so that where it ends depends on the clip only)
    assert cli_main(["run", "--source", f"bvh:{cmu}", "--duration", "80000", "--continue-after-fall",
                     "--out", str(out)]) == 0
    assert "ends (with its rest) at 5.85 s" in capsys.readouterr().err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["sim_duration_s"] == pytest.approx(5.85, abs=0.01)
    # A walk's feet land 0.1-0.2 m apart across his pelvis (scaled); the character's width is measured alike
    assert 0.08 < metrics["step_width_m"]["operator"] < 0.2
    assert isinstance(metrics["step_width_m"]["character"], float)


def test_a_run_shorter_than_its_operator_worker_start_prints_nothing_but_its_result(tmp_path):
    import subprocess
    import sys

    for k in range(3):
        proc = subprocess.run([sys.executable, "-m", "stylesync.cli", "demo", "--duration", "1e-6", "--out",
                               str(tmp_path / f"o{k}")], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0
        assert "Exception ignored" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr


def test_exit_codes_input_two_running_one_and_debug_keeps_the_traceback(tmp_path, capsys, monkeypatch):
    from stylesync import cli
    from stylesync.errors import SimulationError

    assert cli_main(["replay", str(tmp_path / "none.jsonl"), "--export-bvh", str(tmp_path / "x.bvh")]) == 2  # input

    def failing(args):
        raise SimulationError("the engine refused the character")

    monkeypatch.setattr(cli, "_demo", failing)
    capsys.readouterr()
    assert cli_main(["demo", "--out", str(tmp_path / "d")]) == 1  # a failure while running
    assert capsys.readouterr().err.strip() == "stylesync: error: the engine refused the character"
    with pytest.raises(SimulationError):
        cli_main(["--debug", "demo", "--out", str(tmp_path / "d")])


@pytest.mark.parametrize("metrics, session", [("{garbage", b"\x00\xff"), ("[1, 2", b"[1]\n"), ('"text"', b"null\n"),
                                              ("{}", b'{"format": "stylesync-session", "config": 3}\n')])
def test_a_report_on_a_damaged_folder_is_written_and_says_so(tmp_path, capsys, metrics, session):
    (tmp_path / "metrics.json").write_text(metrics)
    (tmp_path / "bench.json").write_text(metrics)
    (tmp_path / "session.jsonl").write_bytes(session)
    assert cli_main(["report", str(tmp_path)]) == 0
    text = (tmp_path / "report.html").read_text()
    assert metrics == "{}" or "not readable as JSON" in text or "not a JSON object" in text


def test_follow_path_and_in_place_are_taken_and_recorded(tmp_path, capsys):
    """``--follow-path`` keeps the targets' pull onto his path at every speed of his (the defaults pull them while he
    goes slower than the character's gait, and follow his path by the landings),
    ``--in-place`` sets the settings before that; each run's session file records them, and the two together are
    refused with one line."""
    from stylesync.config import FOLLOW_PATH_MOTION, IN_PLACE_MOTION, IN_PLACE_OPERATOR, IN_PLACE_WHOLE_BODY
    from stylesync.export.session_file import read_session

    for name in ("fp", "ip", "plain"):
        flags = {"fp": ["--follow-path"], "ip": ["--in-place"], "plain": []}[name]
        assert cli_main(["demo", *flags, "--duration", "0.2", "--out", str(tmp_path / name)]) == 0
    header = {name: read_session(tmp_path / name / "session.jsonl").header for name in ("fp", "ip", "plain")}
    follow, in_place, plain = (header[n]["config"] for n in ("fp", "ip", "plain"))
    for name, value in FOLLOW_PATH_MOTION.items():
        assert follow["motion"][name] == value
    assert follow["motion"]["path_target_fade_from_mps"] is None
    assert plain["motion"]["path_target_fade_from_mps"] is not None and plain["motion"]["path_target_share"] > 0.0
    for section, values in ((("motion",), IN_PLACE_MOTION), (("control", "whole_body"), IN_PLACE_WHOLE_BODY),
                            (("operator",), IN_PLACE_OPERATOR)):
        ip, pl = in_place, plain
        for key in section:
            ip, pl = ip[key], pl[key]
        for name, value in values.items():
            assert ip[name] == value
            assert pl[name] != value, name
    assert plain["operator"]["start_with_clip_velocity"] and not in_place["operator"]["start_with_clip_velocity"]
    metrics = {n: json.loads((tmp_path / n / "metrics.json").read_text()) for n in ("ip", "plain")}
    assert metrics["ip"]["in_place"] and not metrics["plain"]["in_place"]
    assert cli_main(["demo", "--in-place", "--follow-path", "--duration", "0.2", "--out", str(tmp_path / "both")]) == 2
    assert "--in-place and --follow-path" in capsys.readouterr().err


@pytest.mark.parametrize("flag, settings, section", [("--free-swing", "FREE_SWING_MOTION", ("motion",)),
                                                     ("--late-contact-steps", "LATE_CONTACT_STEPS_MOTION", ("motion",)),
                                                     ("--no-track-rise", "NO_TRACK_RISE_WHOLE_BODY",
                                                      ("control", "whole_body")),
                                                     ("--damp-angular-momentum", "DAMP_ANGULAR_MOMENTUM_WHOLE_BODY",
                                                      ("control", "whole_body"))])
def test_a_flag_is_taken_and_recorded(tmp_path, capsys, flag, settings, section):
    """``--free-swing``, ``--late-contact-steps``, ``--no-track-rise`` and ``--damp-angular-momentum`` set their
    settings (config.FREE_SWING_MOTION, LATE_CONTACT_STEPS_MOTION, NO_TRACK_RISE_WHOLE_BODY,
    DAMP_ANGULAR_MOMENTUM_WHOLE_BODY), and the run's session file records them; without the flag the defaults
    differ."""
    from stylesync import config
    from stylesync.export.session_file import read_session

    assert cli_main(["demo", flag, "--duration", "0.2", "--out", str(tmp_path / "on")]) == 0
    assert cli_main(["demo", "--duration", "0.2", "--out", str(tmp_path / "plain")]) == 0
    on = read_session(tmp_path / "on" / "session.jsonl").header["config"]
    plain = read_session(tmp_path / "plain" / "session.jsonl").header["config"]
    for key in section:
        on, plain = on[key], plain[key]
    for name, value in getattr(config, settings).items():
        assert on[name] == value != plain[name]

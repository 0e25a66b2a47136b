"""Bad command lines end with exit 2 and one line naming the option, before anything runs."""

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


def test_an_export_into_a_missing_folder_creates_it(tmp_path, capsys):
    bvh = tmp_path / "new" / "deeper" / "walk.bvh"
    assert cli_main(["demo", "--duration", "0.2", "--out", str(tmp_path / "out"), "--export-bvh", str(bvh)]) == 0
    assert bvh.is_file() and bvh.read_text().startswith("HIERARCHY")

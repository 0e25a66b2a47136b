"""Paired outcomes of two versions over the same runs, and the exact McNemar p-value of their difference."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from scipy.stats import binomtest

from stylesync.metrics.paired_outcomes import mcnemar_exact_p, paired_outcome, paired_table

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def test_the_p_value_is_the_two_sided_sign_test_of_the_discordant_runs():
    assert mcnemar_exact_p(0, 6) == pytest.approx(2 / 64)  # all six one way: 2 * (1/2)^6
    assert mcnemar_exact_p(1, 9) == pytest.approx(2 * (1 + 10) / 1024)
    assert mcnemar_exact_p(8, 8) == 1.0 and mcnemar_exact_p(0, 0) == 1.0 and mcnemar_exact_p(1, 0) == 1.0
    for gained, lost in [(7, 11), (7, 24), (3, 29), (12, 4), (30, 41)]:
        assert mcnemar_exact_p(gained, lost) == mcnemar_exact_p(lost, gained)
        assert mcnemar_exact_p(gained, lost) == pytest.approx(binomtest(gained, gained + lost, 0.5).pvalue)
    assert mcnemar_exact_p(7, 24) < 0.01 < 0.4 < mcnemar_exact_p(7, 11)
    with pytest.raises(ValueError, match=">= 0"):
        mcnemar_exact_p(-1, 3)


def _row(category, clip, seed, version, fell, **extra):
    return {"category": category, "clip": clip, "seed": seed, "version": version, "fell": fell, **extra}


def test_runs_are_paired_by_clip_and_seed():
    """Only runs both versions ran are paired; runs that could not be opened are left out."""
    first = [_row("run", "jog", 0, "a", False), _row("run", "jog", 1, "a", True), _row("run", "jog", 2, "a", False),
             _row("run", "run", 0, "a", True), _row("run", "run", 1, "a", False),
             _row("run", "run", 2, "a", False, error="no such file")]
    second = [_row("run", "jog", 0, "b", False), _row("run", "jog", 1, "b", False), _row("run", "jog", 2, "b", True),
              _row("run", "run", 0, "b", True), _row("run", "run", 2, "b", False), _row("run", "run", 3, "b", False)]
    o = paired_outcome(first, second)
    assert (o.runs, o.both_complete, o.gained, o.lost, o.both_fall) == (4, 1, 1, 1, 1)
    assert o.p_value == 1.0


def test_the_table_pairs_each_version_with_the_first_per_category_and_over_all():
    rows = []
    for seed in range(10):  # runs: the second version completes all ten, the first six; walks: the same
        rows += [_row("run", "jog", seed, "new", False), _row("run", "jog", seed, "old", seed < 6),
                 _row("walk", "walk", seed, "new", False), _row("walk", "walk", seed, "old", False)]
    md = paired_table(rows, ["old", "new"], ("walk", "run", "jump"))
    header, rule, *lines = md.splitlines()
    assert header.count("|") == rule.count("|") == lines[0].count("|")
    cells = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[3:-1]] for line in lines}
    assert set(cells) == {"walk", "run", "all"}  # no jump rows were run
    assert cells["run"] == ["10", "4", "6", "0", "0", "+6", f"{2 / 64:.2g}"]
    assert cells["walk"] == ["10", "10", "0", "0", "0", "+0", "1"]
    assert cells["all"][:6] == ["20", "14", "6", "0", "0", "+6"]
    assert math.isclose(float(cells["all"][6]), 2 / 64, rel_tol=0.05)


def test_the_benchmark_pairs_two_suite_files(tmp_path):
    """benchmarks/paired_outcomes.py reads two dev_suite.json files (the first version of each) and one file's
    versions; a file that is not a suite's is one line."""
    a = [_row("kick", "kick", s, "stylesync", s == 0) for s in range(3)] + [_row("kick", "kick", 0, "plain-pd", True)]
    b = [_row("kick", "kick", s, "stylesync", False) for s in range(3)]
    (tmp_path / "a.json").write_text(json.dumps(a))
    (tmp_path / "b.json").write_text(json.dumps(b))
    (tmp_path / "bad.json").write_text(json.dumps({"rows": [{"clip": "x"}]}))

    def run(*argv):
        return subprocess.run([sys.executable, str(BENCHMARKS / "paired_outcomes.py"), *argv], capture_output=True,
                              text=True, timeout=120)

    two = run(str(tmp_path / "a.json"), str(tmp_path / "b.json"))
    assert two.returncode == 0, two.stderr
    assert "| kick | B | 3 | 2 | 1 | 0 | 0 | +1 | 1 |" in two.stdout
    one = run(str(tmp_path / "a.json"))
    assert one.returncode == 0, one.stderr
    assert "| kick | plain-pd | 1 | 0 | 0 | 0 | 1 | +0 | 1 |" in one.stdout
    bad = run(str(tmp_path / "bad.json"))
    assert bad.returncode != 0 and "not a development suite's dev_suite.json" in bad.stderr

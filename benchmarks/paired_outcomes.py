"""The runs two development-suite results complete and fall on, paired, and whether their difference is more than
chance (prints a table; not a test).

    python benchmarks/paired_outcomes.py out/suite_a/dev_suite.json [out/suite_b/dev_suite.json]
                                         [--first VERSION] [--versions V1,V2,...]

With one file (a suite run of several versions: ``stylesync bench --suite dev`` with the plain PD tracker, or
benchmarks/dev_suite.py with a baseline), its versions are paired against the first (``--first``; by default the
first in the file). With two files (say two suite runs with different settings), the first file's rows are the
version ``A``, the second's ``B``, after keeping only ``--first`` (or the first version) of each. Per category and
over all of them: the runs (clip and seed) both complete, the runs only one completes, both fall, and the exact
McNemar p-value of the difference (stylesync.metrics.paired_outcomes).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from stylesync.metrics.dev_suite import ORDER
from stylesync.metrics.paired_outcomes import paired_table


def _rows(path: str) -> list[dict]:
    rows = json.loads(Path(path).read_text())
    if isinstance(rows, dict):
        rows = rows.get("rows", [])
    if not isinstance(rows, list) or not all(isinstance(r, dict) and {"category", "clip", "seed", "fell"} <= r.keys()
                                             for r in rows if "error" not in r):
        raise SystemExit(f"{path}: not a development suite's dev_suite.json (a list of runs)")
    return rows


def _versions(rows: list[dict]) -> list[str]:
    return list(dict.fromkeys(str(r.get("version", "")) for r in rows))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+", help="one or two dev_suite.json files")
    ap.add_argument("--first", help="the version the others are paired against (default: the first in the file)")
    ap.add_argument("--versions", help="comma-separated versions to pair, from a single file (default: all)")
    args = ap.parse_args()
    if len(args.files) > 2:
        raise SystemExit("give one or two dev_suite.json files")
    if len(args.files) == 2:
        rows = []
        for label, path in zip("AB", args.files, strict=True):
            these = _rows(path)
            keep = args.first or _versions(these)[0]
            rows += [{**r, "version": label} for r in these if str(r.get("version", "")) == keep]
        versions = ["A", "B"]
    else:
        rows = _rows(args.files[0])
        versions = args.versions.split(",") if args.versions else _versions(rows)
        if args.first:
            versions = [args.first] + [v for v in versions if v != args.first]
    unknown = [v for v in versions if not any(str(r.get("version", "")) == v for r in rows)]
    if unknown or len(versions) < 2:
        raise SystemExit(f"need two versions present in the rows; have {', '.join(_versions(rows))}")
    print(paired_table(rows, versions, ORDER))


if __name__ == "__main__":
    main()

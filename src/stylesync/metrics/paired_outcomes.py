"""Paired outcomes of two versions over the same runs, and whether their difference is more than chance (the exact
McNemar test).

A run of the development suite is a clip with a sensor seed, and every version runs the same runs. Two versions'
completion counts differ by ``gained - lost``: ``gained`` the runs the other version completes and the first does
not, ``lost`` the other way round (the discordant runs). A fall of the character is sensitive to small differences:
a change of no physical meaning (a task weight changed in its seventh digit) moves some runs from falling to
completing and others the other way (docs/decisions.md, "How far apart two versions' counts are by chance"). So a
difference of the counts is read against the discordant runs. If the change does not alter a run's chance of
completing, each discordant run goes either way with probability 1/2; the two-sided p-value of the difference is

    p = min(1, 2 * sum_{k <= min(gained, lost)} C(n, k) / 2^n),   n = gained + lost

(the exact McNemar test, a sign test on the discordant runs). A small p (say below 0.05) says the two versions
differ in how often they complete; a large one says the counts' difference is within what chance gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

ORDER_LAST = "all"  # the row over every category


def mcnemar_exact_p(gained: int, lost: int) -> float:
    """The two-sided p-value of ``gained`` against ``lost`` discordant runs under the null hypothesis that each goes
    either way with probability 1/2 (exact McNemar test); 1 when there are none [-]."""
    if gained < 0 or lost < 0:
        raise ValueError(f"discordant counts must be >= 0, got {gained} and {lost}")
    n = gained + lost
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(gained, lost) + 1))
    return min(1.0, 2.0 * tail / 2.0 ** n)


@dataclass(frozen=True)
class PairedOutcome:
    """Two versions' outcomes over the runs both could run (a clip and a seed each) [runs]."""

    runs: int  # runs both versions ran (each opened its clip)
    both_complete: int
    gained: int  # the second version completes, the first falls
    lost: int  # the first completes, the second falls
    both_fall: int

    @property
    def p_value(self) -> float:
        """:func:`mcnemar_exact_p` of the discordant runs [-]."""
        return mcnemar_exact_p(self.gained, self.lost)


def _run_key(row: dict) -> tuple[str, str, int]:
    return str(row["category"]), str(row.get("spec", row["clip"])), int(row["seed"])


def paired_outcome(first: list[dict], second: list[dict]) -> PairedOutcome:
    """The paired outcome of two versions' rows (dev_suite rows: ``category``, ``clip`` or ``spec``, ``seed``,
    ``fell``; rows with an ``error`` are left out), over the runs present in both."""
    a = {_run_key(r): bool(r["fell"]) for r in first if "error" not in r}
    b = {_run_key(r): bool(r["fell"]) for r in second if "error" not in r}
    keys = a.keys() & b.keys()
    return PairedOutcome(
        runs=len(keys),
        both_complete=sum(not a[k] and not b[k] for k in keys),
        gained=sum(a[k] and not b[k] for k in keys),
        lost=sum(not a[k] and b[k] for k in keys),
        both_fall=sum(a[k] and b[k] for k in keys),
    )


def paired_table(rows: list[dict], versions: list[str], categories: tuple[str, ...]) -> str:
    """Markdown: per category (in the order of ``categories``, then over all of them) and for each version after
    the first, its paired outcome against the first (``versions[0]``), with the p-value of the difference."""
    lines = [f"| category | version | against {versions[0]}: runs | both complete | complete, not {versions[0]} | "
             f"{versions[0]} complete, not it | both fall | difference | p (exact McNemar) |",
             "|" + "---|" * 9]
    for cat in (*categories, ORDER_LAST):
        for v in versions[1:]:
            first = [r for r in rows if r["version"] == versions[0] and cat in (ORDER_LAST, r["category"])]
            second = [r for r in rows if r["version"] == v and cat in (ORDER_LAST, r["category"])]
            o = paired_outcome(first, second)
            if o.runs:
                lines.append(f"| {cat} | {v} | {o.runs} | {o.both_complete} | {o.gained} | {o.lost} | {o.both_fall} "
                             f"| {o.gained - o.lost:+d} | {o.p_value:.2g} |")
    return "\n".join(lines)

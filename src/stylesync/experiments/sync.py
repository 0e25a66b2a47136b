"""Experiment ``sync`` (Sec. 7.4.1, Fig. 11): stepping with and without the LIPM time-sync compensation
(Eq. 21-23). Paper: state-transition delay at most 0.172 s with it; 0.798 s and a fall within 3 steps without.

The claim checked: with compensation, no fall and a maximum delay <= 0.172 s; without, a larger maximum delay or a
fall. Exit status 0 only when the claim holds.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from stylesync.config import ControlConfig, OperatorConfig, SessionConfig  # noqa: E402
from stylesync.experiments.common import run_session  # noqa: E402
from stylesync.metrics.plots import save_figure, stance_axes  # noqa: E402
from stylesync.metrics.summary import summarize  # noqa: E402
from stylesync.session import Session  # noqa: E402
from stylesync.sources.builtin_operator import builtin_operator  # noqa: E402

PAPER = {"with_max_delay_s": 0.172, "without_max_delay_s": 0.798, "without_falls_within_steps": 3}


def run(out: Path, duration_s: float = 12.0, seed: int = 0) -> tuple[bool, dict]:
    out.mkdir(parents=True, exist_ok=True)
    results, metrics = {}, {}
    for label, lipm in (("with", True), ("without", False)):
        cfg = SessionConfig(duration_s=duration_s, seed=seed, operator=OperatorConfig(clip="walk"),
                            control=ControlConfig(lipm_time_sync=lipm))
        source, _ = builtin_operator(cfg.operator, cfg.clocks, duration_s + 1.0, seed)
        results[label] = run_session(Session(cfg, source))
        metrics[label] = summarize(results[label])
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for ax, label in zip(axes, ("with", "without"), strict=True):
        stance_axes(ax, results[label].log)
        m = metrics[label]
        ax.set_title(f"{label} LIPM time sync: max delay {m['state_transition_delay_s']['max']:.3f} s, "
                     + (f"fell at {m['fall_time_s']:.2f} s" if m["fell"] else "no fall"))
        ax.legend(loc="upper right")
    axes[-1].set_xlabel("t [s]")
    save_figure(fig, out / "fig11_states.png")
    w, wo = metrics["with"], metrics["without"]
    holds = (not w["fell"] and w["state_transition_delay_s"]["max"] <= PAPER["with_max_delay_s"]
             and (wo["fell"] or wo["state_transition_delay_s"]["max"] > w["state_transition_delay_s"]["max"]))
    summary = {"experiment": "sync", "claim_holds": holds, "paper": PAPER,
               "with": {k: w[k] for k in ("fell", "fall_time_s", "operator_steps", "character_steps",
                                          "state_transition_delay_s")},
               "without": {k: wo[k] for k in ("fell", "fall_time_s", "operator_steps", "character_steps",
                                             "state_transition_delay_s")}}
    (out / "metrics.json").write_text(json.dumps(summary, indent=2))
    return holds, summary

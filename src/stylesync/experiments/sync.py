"""Experiment ``sync`` (Sec. 7.4.1, Fig. 11): stepping with and without the LIPM time-sync compensation
(Eq. 21-23). Paper: state-transition delay at most 0.172 s with it; 0.798 s and a fall within 3 steps without.

The claim checked: with compensation, the built-in walk (the run's seed) does not fall and its maximum delay is
<= 0.172 s; without it, the walk falls, or, where it does not at the operator's own pace, there is an operator
speed or a sensor rate at which the term decides a fall. The speed sweep plays the walk ``SPEEDS`` times faster
(cadence and speed, ``OperatorConfig.playback_speed``), the sensor-rate sweep samples the operator at
``SENSOR_RATES_HZ`` instead of the Kinect's 16 Hz (``ClockConfig.mocap_hz``: the pipeline then interpolates between
frames further apart, as a slower sensor or a lossy link gives it), each over ``SWEEP_SEEDS`` sensor seeds from the
run's; the term decides a fall at a setting where no walk with it falls and most walks without it do. A constant
sensor latency is not swept: it delays the whole operator alike, and the character follows the delayed stream as it
follows the live one (measured once at 0.1-0.4 s, no fall either way: docs/decisions.md). Exit status 0 only when the
claim holds.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stylesync.config import ClockConfig, ControlConfig, OperatorConfig, SessionConfig  # noqa: E402
from stylesync.experiments.common import run_session  # noqa: E402
from stylesync.metrics.plots import save_figure, stance_axes  # noqa: E402
from stylesync.metrics.summary import summarize  # noqa: E402
from stylesync.session import Session, SessionResult  # noqa: E402
from stylesync.sources.builtin_operator import builtin_operator  # noqa: E402

PAPER = {"with_max_delay_s": 0.172, "without_max_delay_s": 0.798, "without_falls_within_steps": 3}
SPEEDS = (1.0, 1.2, 1.4, 1.6, 1.8)  # operator speed, times the clip's [-]
SENSOR_RATES_HZ = (10.0, 8.0, 6.0, 4.0)  # the operator's sensor rate, at his own speed [Hz]
SWEEP_SEEDS = 4
_LABELS = (("with", True), ("without", False))
_KEYS = ("fell", "fall_time_s", "operator_steps", "character_steps", "state_transition_delay_s")


def _walk(lipm: bool, speed: float, duration_s: float, seed: int, sensor_hz: float | None = None) -> SessionResult:
    """The built-in walk at ``speed`` times the clip's pace, with or without the LIPM term, its operator sampled at
    ``sensor_hz`` (None: the Kinect's rate)."""
    clocks = ClockConfig() if sensor_hz is None else ClockConfig(mocap_hz=sensor_hz)
    cfg = SessionConfig(duration_s=duration_s, seed=seed, operator=OperatorConfig(clip="walk", playback_speed=speed),
                        control=ControlConfig(lipm_time_sync=lipm), clocks=clocks)
    source, _ = builtin_operator(cfg.operator, cfg.clocks, duration_s + 1.0, seed)
    return run_session(Session(cfg, source))


def speed_sweep(duration_s: float, seed: int, first: dict[str, dict] | None = None) -> list[dict]:
    """Per speed of ``SPEEDS``: the runs with and without the term over ``SWEEP_SEEDS`` seeds from ``seed`` (fell,
    fall time, maximum delay), and whether the term decides a fall there. ``first``: the summaries already run at
    speed 1.0 and ``seed`` (label -> summary), reused."""
    return _sweep("speed", SPEEDS, lambda lipm, speed, k: (
        first[_label(lipm)] if first is not None and speed == 1.0 and k == 0
        else summarize(_walk(lipm, speed, duration_s, seed + k))), seed)


def sensor_rate_sweep(duration_s: float, seed: int) -> list[dict]:
    """Per sensor rate of ``SENSOR_RATES_HZ`` (the operator at his own speed): as :func:`speed_sweep`."""
    return _sweep("sensor_hz", SENSOR_RATES_HZ,
                  lambda lipm, hz, k: summarize(_walk(lipm, 1.0, duration_s, seed + k, sensor_hz=hz)), seed)


def deciding_settings(rows: list[dict], key: str) -> list[float]:
    """The values of ``key`` in a sweep's ``rows`` at which the term decides a fall."""
    return [r[key] for r in rows if r["term_decides_fall"]]


def _label(lipm: bool) -> str:
    return next(label for label, on in _LABELS if on == lipm)


def _sweep(key: str, values: tuple[float, ...], summary_of: Callable[[bool, float, int], dict],
           seed: int) -> list[dict]:
    """Per value of the swept setting ``key``: the runs with and without the term over ``SWEEP_SEEDS`` seeds from
    ``seed`` (``summary_of(lipm, value, k)``: the summary of the k-th), and whether the term decides a fall there."""
    rows = []
    for value in values:
        row: dict = {key: value}
        for label, lipm in _LABELS:
            runs = []
            for k in range(SWEEP_SEEDS):
                m = summary_of(lipm, value, k)
                runs.append({"seed": seed + k, "fell": bool(m["fell"]), "fall_time_s": m["fall_time_s"],
                             "max_delay_s": m["state_transition_delay_s"]["max"]})
            row[label] = runs
        falls_with = sum(r["fell"] for r in row["with"])
        falls_without = sum(r["fell"] for r in row["without"])
        row["term_decides_fall"] = falls_with == 0 and falls_without > SWEEP_SEEDS / 2
        rows.append(row)
    return rows


# The swept settings, by their key in a sweep's rows: (axis label, bar width in the setting's unit)
_SWEPT = {"speed": ("operator speed [x clip]", 0.08), "sensor_hz": ("operator's sensor rate [Hz]", 0.8)}


def _plot_sweep(rows: list[dict], key: str, path: Path) -> None:
    xlabel, width = _SWEPT[key]
    fig, (ax_f, ax_d) = plt.subplots(1, 2, figsize=(10, 3.8))
    values = np.array([r[key] for r in rows])
    for i, (label, _) in enumerate(_LABELS):
        falls = [sum(x["fell"] for x in r[label]) for r in rows]
        delays = [float(np.median([x["max_delay_s"] for x in r[label]])) for r in rows]
        ax_f.bar(values + (i - 0.5) * width, falls, width=width, label=f"{label} LIPM time sync")
        ax_d.plot(values, delays, "o-", label=f"{label} LIPM time sync")
    ax_f.set_xlabel(xlabel)
    ax_f.set_ylabel(f"runs that fall (of {SWEEP_SEEDS})")
    ax_f.set_ylim(0, SWEEP_SEEDS)
    ax_f.legend(loc="upper left")
    ax_d.axhline(PAPER["with_max_delay_s"], color="k", lw=0.8, ls="--", label="paper, with (0.172 s)")
    ax_d.set_xlabel(xlabel)
    ax_d.set_ylabel("median of the runs' max delay [s]")
    ax_d.legend(loc="upper left")
    save_figure(fig, path)


def run(out: Path, duration_s: float = 12.0, seed: int = 0) -> tuple[bool, dict]:
    out.mkdir(parents=True, exist_ok=True)
    results = {label: _walk(lipm, 1.0, duration_s, seed) for label, lipm in _LABELS}
    metrics = {label: summarize(r) for label, r in results.items()}
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for ax, (label, _) in zip(axes, _LABELS, strict=True):
        stance_axes(ax, results[label].log)
        m = metrics[label]
        ax.set_title(f"{label} LIPM time sync: max delay {m['state_transition_delay_s']['max']:.3f} s, "
                     + (f"fell at {m['fall_time_s']:.2f} s" if m["fell"] else "no fall"))
        ax.legend(loc="upper right")
    axes[-1].set_xlabel("t [s]")
    save_figure(fig, out / "fig11_states.png")
    w, wo = metrics["with"], metrics["without"]
    with_holds = not w["fell"] and w["state_transition_delay_s"]["max"] <= PAPER["with_max_delay_s"]
    sweep: list[dict] = []
    rate_sweep: list[dict] = []
    if with_holds and not wo["fell"]:
        sweep = speed_sweep(duration_s, seed, metrics)
        _plot_sweep(sweep, "speed", out / "speed_sweep.png")
    deciding = deciding_settings(sweep, "speed")
    if with_holds and not wo["fell"] and not deciding:
        rate_sweep = sensor_rate_sweep(duration_s, seed)
        _plot_sweep(rate_sweep, "sensor_hz", out / "sensor_rate_sweep.png")
    deciding_rates = deciding_settings(rate_sweep, "sensor_hz")
    holds = with_holds and (wo["fell"] or bool(deciding) or bool(deciding_rates))
    summary = {"experiment": "sync", "claim_holds": holds, "paper": PAPER,
               "with": {k: w[k] for k in _KEYS}, "without": {k: wo[k] for k in _KEYS},
               "speed_sweep": sweep, "speeds_where_the_term_decides_a_fall": deciding,
               "sensor_rate_sweep": rate_sweep, "sensor_rates_where_the_term_decides_a_fall": deciding_rates}
    (out / "metrics.json").write_text(json.dumps(summary, indent=2))
    return holds, summary

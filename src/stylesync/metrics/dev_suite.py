"""``stylesync bench --suite dev``: every shared clip, a category per clip, several sensor seeds, per category.

Clips: the humanoid3d clips of pybullet_data (played by the built-in operator) and every clip of
``../shared/mocap`` (``cmu``, ``cmu-dev`` BVH, ``deepmimic``), each with a category (walk, styled walk, uneven,
run, jump, kick, arms, acrobatics; from the clips' READMEs and names). Each clip runs through the Kinect sensor
model with seeds 0 .. N-1, with this version (``stylesync``) and the plain PD tracker (``plain-pd``, bench.py) in
the same run, the same settings for every clip. A run lasts the clip (at most ``duration_s``; the 1 s standing
lead-in of a clip, or the 3 s rest after a recorded file, included). Per category and controller: runs, clips that
could be opened, completion (no fall through the clip and the rest), runs through the clip (no fall before its
end), runs without a UHC/PHC termination, mean fall time, MPJPE (global, root-relative), steps (character /
operator) and the median of the runs' largest transition delays; then, per category, the runs each version
completes and the other does not, with the p-value of the difference (paired_outcomes.py). Written as
dev_suite.md, dev_suite.json and report.html. The previous version of the code in the same run:
``benchmarks/dev_suite.py --baseline REF`` (git worktrees). A user's own clips beside them or alone
(``--clips INPUT [--clips-only]``): :func:`user_clip_specs`.
"""

from __future__ import annotations

import dataclasses
import json
import logging
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig, follow_path, in_place, pelvis_joint
from stylesync.errors import StylesyncError
from stylesync.metrics.bench import CONTROLLERS
from stylesync.metrics.imitation import TERMINATION_CAUSES
from stylesync.metrics.paired_outcomes import paired_table
from stylesync.metrics.summary import summarize
from stylesync.session import FALL_REASON_PREFIXES

if TYPE_CHECKING:
    from stylesync.sources.registry import OpenedSource

# Category of each clip, from the clips' READMEs (../shared/mocap/*/README.md) and the humanoid3d clip names.
CATEGORIES = {
    "walk": "walk", "stealthy_walk": "styled walk", "long_humanoid3d_stealthy_walk0": "styled walk",
    "zombie_walk": "styled walk", "jog": "run", "run": "run", "jump": "jump", "kick": "kick", "spinkick": "kick",
    "punch": "arms", "dance_a": "arms", "dance_b": "arms", "spin": "arms", "backflip": "acrobatics",
    "cartwheel": "acrobatics", "crawl": "acrobatics", "getup_facedown": "acrobatics",
    "getup_faceup": "acrobatics", "roll": "acrobatics",
    "02_01": "walk", "131_01": "styled walk", "131_02": "styled walk", "131_03": "jump",
    "02_02": "walk", "05_01": "walk", "06_01": "walk", "07_01": "walk", "07_05": "walk", "07_11": "walk",
    "08_01": "walk", "08_04": "walk", "08_08": "walk", "10_04": "walk", "12_01": "walk", "08_07": "styled walk",
    "03_01": "uneven", "03_02": "uneven", "02_03": "run", "09_01": "run", "09_06": "run", "09_11": "run",
    "02_04": "jump", "13_11": "jump", "13_32": "jump", "13_39": "jump", "13_41": "jump", "jumping_jacks": "jump",
}
ORDER = ("walk", "styled walk", "uneven", "run", "jump", "kick", "arms", "acrobatics", "other")
SUITE_CONTROLLERS = ("stylesync", "plain-pd")
# The stylesync controller with `--follow-path`'s settings (config.follow_path): `stylesync bench --suite dev
# --follow-path` runs it beside the others, in the same run
FOLLOW_PATH_VERSION = "follow-path"
# ... and with `--in-place`'s (config.in_place): `stylesync bench --suite dev --in-place`
IN_PLACE_VERSION = "in-place"
# ... and with `--pelvis-joint`'s (config.pelvis_joint): `stylesync bench --suite dev --pelvis-joint`
PELVIS_JOINT_VERSION = "pelvis-joint"
# The stylesync controller's versions with a set of settings, and the function that sets them
VERSION_SETTINGS = {FOLLOW_PATH_VERSION: follow_path, IN_PLACE_VERSION: in_place, PELVIS_JOINT_VERSION: pelvis_joint}


def category_of_folder(name: str) -> str | None:
    """The suite's category a folder's name gives (``walk``, ``styled_walk``, ``Styled-Walk``, ...), or None."""
    key = " ".join(name.lower().replace("_", " ").replace("-", " ").split())
    return key if key in ORDER else None


def user_clip_specs(input_spec: str) -> list[tuple[str, str, str]]:
    """(spec, name, category) of a user's own clips, found as `stylesync batch` finds them
    (sources/clip_files.find_clips: a folder searched recursively, a glob pattern, a list file or one clip file;
    each file's source kind from its suffix). Its name is its path without the suffix, relative to the folder the
    clips share; its category that of the nearest folder around it, up to and including that shared folder, named
    after one (:func:`category_of_folder`: ``mine/walk/a.bvh`` is a walk, and so is every clip of ``--clips
    mine/walk``), otherwise ``other``."""
    import os

    from stylesync.sources.clip_files import KIND_BY_SUFFIX, find_clips

    files = find_clips(input_spec)
    common = Path(os.path.commonpath([f.parent for f in files]))
    out = []
    for f in files:
        rel = f.relative_to(common)
        folders = (common.name, *rel.parts[:-1])  # outermost first
        category = next((c for c in map(category_of_folder, reversed(folders)) if c is not None), "other")
        out.append((f"{KIND_BY_SUFFIX[f.suffix.lower()]}:{f}", rel.with_suffix("").as_posix(), category))
    return out


def clip_specs(mocap: Path | None) -> list[tuple[str, str, str]]:
    """(spec, name, category) of every clip of the suite; ``mocap``: the shared mocap folder (or None)."""
    import pybullet_data

    motions = Path(pybullet_data.getDataPath()) / "data" / "motions"
    out = [(f"builtin:{p.stem.removeprefix('humanoid3d_')}", p.stem.removeprefix("humanoid3d_"))
           for p in sorted(motions.glob("humanoid3d_*.txt"))]
    if mocap is not None:
        for folder in ("cmu", "cmu-dev"):
            out += [(f"bvh:{p}", p.stem) for p in sorted((mocap / folder).glob("*.bvh"))]
        for p in sorted((mocap / "deepmimic").glob("*.txt")):
            name = p.stem.removeprefix("humanoid3d_")
            out.append((f"deepmimic:{p}", name if not p.stem.startswith("long_") else p.stem))
    return [(spec, name, CATEGORIES.get(name, "other")) for spec, name in out]


def suite_config(spec: str, opened: OpenedSource, seed: int, duration_s: float,
                 operator: OperatorConfig | None = None) -> tuple[SessionConfig, float]:
    """A suite run's configuration for the opened source ``spec`` (default settings, or ``operator``'s, e.g. his
    mirror image; the source's frame rate, at most ``duration_s``, the rest after a recorded file included) and the
    time its clip ends [s]."""
    op = operator or OperatorConfig()
    length = min(duration_s, float(opened.duration_s or duration_s))
    in_motion = spec.startswith(("bvh:", "k4a-json:")) and op.start_in_motion
    clip_end = length - (min(op.rest_after_clip_s, length) if in_motion else 0.0)
    cfg = SessionConfig(duration_s=length, seed=seed, operator=op,
                        clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz))
    return cfg, clip_end


def run_clip(spec: str, seed: int, duration_s: float, controller: str,
             operator: OperatorConfig | None = None) -> dict:
    """One run of the suite: the clip through the Kinect sensor model with ``seed`` (its noise and the operator
    options from ``operator``, by default the default's); a clip that cannot be opened gives ``{"error": ...}``."""
    from stylesync.session import run_and_release
    from stylesync.sources.registry import open_source

    logging.disable(logging.WARNING)
    settings = VERSION_SETTINGS.get(controller)
    control, motion = CONTROLLERS["stylesync" if settings is not None else controller]
    try:
        opened = open_source(spec, operator=operator, seed=seed, duration_s=duration_s)
    except StylesyncError as exc:
        return {"error": str(exc)[:200]}
    cfg, clip_end = suite_config(spec, opened, seed, duration_s, operator)
    cfg = dataclasses.replace(cfg, control=control, motion=motion)
    if settings is not None:
        cfg = settings(cfg)
    result = run_and_release(cfg, opened.source)
    m = summarize(result)
    keys = ("fell", "fall_time_s", "sim_duration_s", "operator_steps", "character_steps",
            "state_transition_delay_s", "mpjpe_global_mm", "mpjpe_root_mm", "mpjpe_global_before_uhc_mm",
            "mpjpe_root_before_uhc_mm", "uhc_fall_time_s", "uhc_cause", "path_progress", "realtime_factor",
            "fall_reason", "step_width_m")
    return {"clip_end_s": clip_end, **{k: m.get(k) for k in keys}}


def _job(job: tuple) -> dict:
    spec, name, cat, seed, controller, duration_s, operator = job
    return {"clip": name, "spec": spec, "category": cat, "seed": seed, "version": controller,
            **operator_variant(operator), **run_clip(spec, seed, duration_s, controller, operator)}


def operator_variant(operator: OperatorConfig | None) -> dict:
    """How ``operator`` differs from the suite's default operator, for the rows: ``mirror`` (his mirror image) and
    ``sensor_noise`` (the sensor model's position noise over the default's); {} for the default."""
    if operator is None:
        return {}
    default = OperatorConfig()
    out: dict = {}
    if operator.mirror:
        out["mirror"] = True
    if (operator.position_noise_m, operator.orientation_noise_rad) != (default.position_noise_m,
                                                                       default.orientation_noise_rad):
        out["sensor_noise"] = round(operator.position_noise_m / default.position_noise_m, 6)
    return out


def _share(k: int, n: int) -> str:
    return f"{100 * k / n:.0f} % ({k}/{n})" if n else "-"


def _mean(values: list[float], fmt: str) -> str:
    return format(float(np.mean(values)), fmt) if values else "-"


def _median(values: list[float], fmt: str) -> str:
    return format(float(np.median(values)), fmt) if values else "-"


def fall_endings(rs: list[dict]) -> str:
    """The falls of ``rs`` counted by how their reason begins (session.FALL_REASON_PREFIXES), as
    ``low/touched/diverged``; a fall whose reason was not recorded (a version before it was kept) is counted
    nowhere."""
    reasons = [str(r.get("fall_reason") or "") for r in rs if r.get("fell")]
    return "/".join(str(sum(reason.startswith(prefix) for reason in reasons)) for prefix in FALL_REASON_PREFIXES)


def termination_causes(rs: list[dict]) -> str:
    """The UHC terminations of the runs of ``rs`` that did not fall, counted by their cause
    (imitation.termination_split), as ``behind/ahead/aside/height/pose/in place``; a termination whose cause was
    not recorded (a version before it was kept) is counted nowhere."""
    causes = [r.get("uhc_cause") for r in rs if not r.get("fell") and r.get("uhc_fall_time_s") is not None]
    return "/".join(str(causes.count(c)) for c in TERMINATION_CAUSES)


def category_row(cat: str, version: str, rs: list[dict]) -> str:
    """One row of the per-category table (runs that could not be opened are counted, not averaged)."""
    ok = [r for r in rs if "error" not in r]
    n = len(ok)
    complete = sum(not r["fell"] for r in ok)
    through_clip = sum(not r["fell"] or r["fall_time_s"] >= r.get("clip_end_s", np.inf) for r in ok)
    no_uhc = sum(not r["fell"] and r["uhc_fall_time_s"] is None for r in ok)
    falls = [r["fall_time_s"] for r in ok if r["fell"]]
    delays = [r["state_transition_delay_s"]["max"] for r in ok if r["state_transition_delay_s"]["count"]]
    cells = [cat, version, str(len(rs)), str(n), _share(complete, n), _share(through_clip, n), _share(no_uhc, n),
             termination_causes(ok), _mean(falls, ".2f"), fall_endings(ok),
             _mean([r["mpjpe_global_mm"] for r in ok if r.get("mpjpe_global_mm") is not None], ".0f"),
             _mean([r["mpjpe_root_mm"] for r in ok if r.get("mpjpe_root_mm") is not None], ".0f"),
             _before_termination(ok),
             f"{sum(r['character_steps'] for r in ok)}/{sum(r['operator_steps'] for r in ok)}",
             _median([r["path_progress"] for r in ok if r.get("path_progress") is not None], ".2f"),
             f"{np.median(delays):.3f}" if delays else "-", _step_widths(ok)]
    return "| " + " | ".join(cells) + " |"


def _before_termination(rs: list[dict]) -> str:
    """"global / root-relative": the means over runs of the MPJPE before the UHC termination
    (imitation.mpjpe_before_termination_mm) [mm], "-" where no run has it (a version before it was kept)."""
    return " / ".join(_mean([r[k] for r in rs if r.get(k) is not None], ".0f")
                      for k in ("mpjpe_global_before_uhc_mm", "mpjpe_root_before_uhc_mm"))


def _step_widths(rs: list[dict]) -> str:
    """"character / operator": the medians over runs of each run's median step width [m] (summary.py), "-" where
    no run has one (a version before it was kept, or no step)."""
    def median_of(who: str) -> str:
        return _median([r["step_width_m"][who] for r in rs
                        if r.get("step_width_m") and r["step_width_m"].get(who) is not None], ".3f")
    return f"{median_of('character')} / {median_of('operator')}"


def table(rows: list[dict], versions: list[str]) -> str:
    """The per-category Markdown table, one row per category and version (controller or code version)."""
    lines = ["| category | version | runs | opened | complete (no fall) | through the clip (no fall before its end) | "
             "no UHC termination | UHC terminations: behind / ahead / aside / height / pose / in place | "
             "mean fall time [s] | falls: pelvis low / other link down / diverged | "
             "MPJPE global [mm] | MPJPE root-rel. [mm] | MPJPE global / root-rel. before the termination [mm] | "
             "steps char/op | along his path, median | max delay median [s] | step width char / op, median [m] |",
             "|" + "---|" * 17]
    for cat in ORDER:
        for v in versions:
            rs = [r for r in rows if r["category"] == cat and r["version"] == v]
            if rs:
                lines.append(category_row(cat, v, rs))
    return "\n".join(lines)


def run_dev_suite(out: Path, seeds: int, duration_s: float, mocap: Path | None, only: tuple[str, ...] = (),
                  controllers: tuple[str, ...] = SUITE_CONTROLLERS, workers: int = 2,
                  executor: str | None = None, first_seed: int = 0, operator: OperatorConfig | None = None,
                  clips: list[tuple[str, str, str]] | None = None) -> dict:
    """Run the suite on the sensor seeds ``first_seed`` .. ``first_seed + seeds - 1`` on the executors of
    parallel.py ("processes" by default, "ray", or "inline" when ``workers`` is 1), with ``operator``'s options if
    given (every clip's mirror image, a noisier sensor: :func:`operator_variant`), on ``clips`` ((spec, name,
    category) each) if given instead of :func:`clip_specs`'s; writes dev_suite.md and dev_suite.json under ``out``
    and returns {"rows", "table"}."""
    from stylesync.parallel import execute_all

    out.mkdir(parents=True, exist_ok=True)
    clips = [c for c in (clip_specs(mocap) if clips is None else clips) if not only or c[2] in only]
    jobs = [(spec, name, cat, seed, ctrl, duration_s, operator) for spec, name, cat in clips
            for seed in range(first_seed, first_seed + seeds)
            for ctrl in controllers]
    executor = executor or ("processes" if workers > 1 else "inline")
    rows = [row if isinstance(row, dict) else {"clip": name, "spec": spec, "category": cat, "seed": seed,
                                               "version": ctrl, "error": note}
            for (row, note), (spec, name, cat, seed, ctrl, _, _) in zip(
                execute_all(_job, [(j,) for j in jobs], executor, workers), jobs, strict=True)]
    md = table(rows, list(controllers))
    variant = operator_variant(operator)
    if variant.get("mirror"):
        md = "Every clip mirrored left-right (`--mirror`: his right side drives the character's left).\n\n" + md
    if "sensor_noise" in variant and operator is not None:
        md = (f"The sensor model's noise {variant['sensor_noise']:g} times the default's (`--sensor-noise`: "
              f"{operator.position_noise_m * 1000:g} mm, {operator.orientation_noise_rad:g} rad).\n\n" + md)
    if len(controllers) > 1:
        md += "\n\n" + paired_table(rows, list(controllers), ORDER)
    (out / "dev_suite.json").write_text(json.dumps(rows, indent=1))
    (out / "dev_suite.md").write_text(md + "\n")
    return {"rows": rows, "table": md}

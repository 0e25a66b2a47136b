"""Runs a batch's jobs on Ray, on local processes or in this process, and writes each result as it comes back.

Outputs under OUT: ``clips/NAME/`` per job (``session.jsonl``, ``metrics.json``, ``motion.bvh``, ``motion.mp4``
on request, and ``result.json``, written last: the job is done), and the batch's summary (``batch.json``,
``batch.md``, ``report.html``). A job whose ``result.json`` exists is skipped when the batch is run again (its key
holds the clip's content and the settings), so an interrupted batch continues where it stopped and no clip runs
twice. A job that fails on its input (a bad file, an unknown skeleton) is a result with its one-line error; a job
whose worker or node dies is submitted again, at most ``max_retries`` times.

Executors: ``ray`` (a local Ray started for the batch with one worker per core, or ``ray_address`` to join a
cluster whose nodes have stylesync installed), ``processes`` (a local process pool, when Ray is not installed),
``inline`` (one job after another in this process).
"""

from __future__ import annotations

import json
import logging
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stylesync.batch.clips import BatchSettings, Job
from stylesync.batch.job import run_job
from stylesync.errors import ConfigError
from stylesync.files import write_atomically
from stylesync.parallel import EXECUTORS, execute

log = logging.getLogger("stylesync.batch")


@dataclass
class BatchCounts:
    total: int = 0
    skipped: int = 0  # done by an earlier run of the batch
    done: int = 0
    failed: int = 0
    retried: int = 0
    started_s: float = field(default_factory=time.perf_counter)

    def line(self) -> str:
        """The progress line: jobs done, failures, jobs per minute and the time left."""
        elapsed = time.perf_counter() - self.started_s
        finished = self.done + self.failed
        rate = 60.0 * finished / elapsed if elapsed > 0 and finished else 0.0
        left = self.total - self.skipped - finished
        eta = f"{left / rate:.1f} min" if rate > 0 else "-"
        return (f"batch: {finished + self.skipped}/{self.total} ({self.skipped} from before), {self.failed} failed, "
                f"{self.retried} retried, {rate:.1f} clips/min, ETA {eta}")


def write_result(out: Path, result: dict) -> None:
    """A job's files under OUT/clips/NAME; ``result.json`` last."""
    folder = out / "clips" / result["name"]
    folder.mkdir(parents=True, exist_ok=True)
    if result.get("session") is not None:
        write_atomically(folder / "session.jsonl", result["session"])
    if result.get("metrics") is not None:
        write_atomically(folder / "metrics.json", json.dumps(result["metrics"], indent=2))
    if result.get("bvh") is not None:
        write_atomically(folder / "motion.bvh", result["bvh"])
    if result.get("mp4") is not None:
        write_atomically(folder / "motion.mp4", result["mp4"])
    summary = {k: result[k] for k in ("key", "name", "clip", "seed", "group", "status", "error")}
    summary["metrics"] = _headline(result.get("metrics"))
    write_atomically(folder / "result.json", json.dumps(summary, indent=2))


def _headline(metrics: dict | None) -> dict | None:
    if metrics is None:
        return None
    keys = ("fell", "fall_time_s", "sim_duration_s", "mpjpe_global_mm", "mpjpe_root_mm", "uhc_fall_time_s",
            "path_progress", "foot_skate_mm", "operator_steps", "character_steps", "realtime_factor")
    return {k: metrics.get(k) for k in keys}


def read_result(out: Path, job: Job) -> dict | None:
    """The result an earlier run left for ``job`` (None: not done)."""
    path = out / "clips" / job.name / "result.json"
    try:
        result = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return result if isinstance(result, dict) and result.get("key") == job.key else None


def _call_run_job(job: Job, settings: BatchSettings) -> dict:
    return run_job(job, settings)


def run_batch(jobs: list[Job], settings: BatchSettings, out: Path, executor: str = "ray", workers: int | None = None,
              ray_address: str | None = None, max_retries: int = 2,
              progress: Callable[[BatchCounts], None] | None = None) -> BatchCounts:
    """Run the jobs not done yet, write each result as it comes back, then the summary. Returns the counts."""
    if executor not in EXECUTORS:
        raise ConfigError(f"unknown executor '{executor}' (one of {', '.join(EXECUTORS)})")
    out.mkdir(parents=True, exist_ok=True)
    counts = BatchCounts(total=len(jobs))
    todo = []
    for job in jobs:
        if read_result(out, job) is not None:
            counts.skipped += 1
        else:
            todo.append(job)
    # run_job looked up when the batch runs (tests count the calls by replacing it)
    stream = execute(run_job if executor != "inline" else _call_run_job, [(job, settings) for job in todo],
                     executor, workers, ray_address, max_retries)
    try:
        for k, returned, note in stream:
            job = todo[k]
            if note == "retry":
                counts.retried += 1
                log.warning("batch: %s: its worker was lost; submitted again", job.name)
            else:
                result: dict = returned if isinstance(returned, dict) else {}
                if not result:
                    result = {"key": job.key, "name": job.name, "clip": str(job.clip), "seed": job.seed,
                              "group": job.group, "status": "failed", "error": note}
                write_result(out, result)
                if result["status"] == "ok":
                    counts.done += 1
                else:
                    counts.failed += 1
                    log.warning("batch: %s: %s", job.name, result["error"])
            if progress is not None:
                progress(counts)
    finally:
        write_summary(out, jobs, settings, counts)
    return counts


def _share(k: int, n: int) -> str:
    return f"{100 * k / n:.0f} % ({k}/{n})" if n else "-"


def _mean(values: list[float], fmt: str) -> str:
    return format(float(np.mean(values)), fmt) if values else "-"


def _median(values: list[float], fmt: str) -> str:
    return format(float(np.median(values)), fmt) if values else "-"


def write_summary(out: Path, jobs: list[Job], settings: BatchSettings, counts: BatchCounts) -> dict:
    """batch.json, batch.md and report.html: per folder of clips, runs done and failed, completion (no fall),
    runs without a UHC termination, mean fall time, MPJPE, foot skating, how far along the operator's path."""
    results = [r for r in (read_result(out, job) for job in jobs) if r is not None]
    groups: dict[str, list[dict]] = {}
    for r in results:
        groups.setdefault(r["group"], []).append(r)
    header = ("| clips in | runs | failed | complete (no fall) | no UHC termination | mean fall time [s] | "
              "MPJPE global [mm] | MPJPE root-rel. [mm] | foot skate [mm] | along his path, median |")
    lines = [header, "|" + "---|" * 10]
    for group, rs in sorted(groups.items()):
        ok = [r["metrics"] for r in rs if r["status"] == "ok" and r.get("metrics")]
        falls = [m["fall_time_s"] for m in ok if m.get("fell") and m.get("fall_time_s") is not None]
        complete = sum(1 for m in ok if not m.get("fell"))
        no_uhc = sum(1 for m in ok if m.get("uhc_fall_time_s") is None)
        col = {k: [m[k] for m in ok if m.get(k) is not None] for k in ("mpjpe_global_mm", "mpjpe_root_mm",
                                                                        "foot_skate_mm", "path_progress")}
        lines.append(f"| {group} | {len(rs)} | {len(rs) - len(ok)} | {_share(complete, len(ok))} | "
                     f"{_share(no_uhc, len(ok))} | "
                     f"{_mean(falls, '.2f')} | {_mean(col['mpjpe_global_mm'], '.0f')} | "
                     f"{_mean(col['mpjpe_root_mm'], '.0f')} | {_mean(col['foot_skate_mm'], '.1f')} | "
                     f"{_median(col['path_progress'], '.2f')} |")
    failures = [f"- {r['name']}: {r['error']}" for r in results if r["status"] != "ok"]
    text = (f"# stylesync batch\n\n{len(results)} of {counts.total} runs have a result ({counts.failed} failed this "
            f"time, {counts.retried} retried, {counts.skipped} from an earlier run).\n\n" + "\n".join(lines) + "\n"
            + ("\n## Failed\n\n" + "\n".join(failures) + "\n" if failures else ""))
    summary = {"settings": settings.as_dict(), "total": counts.total, "with_result": len(results),
               "done_now": counts.done, "failed_now": counts.failed, "retried": counts.retried,
               "skipped": counts.skipped, "runs": results}
    write_atomically(out / "batch.json", json.dumps(summary, indent=2))
    write_atomically(out / "batch.md", text)
    rows = "".join("<tr>" + "".join(f"<td>{c.strip()}</td>" for c in line.strip("|").split("|")) + "</tr>"
                   for line in lines if not line.startswith("|---"))
    fails = "".join(f"<li>{f[2:]}</li>" for f in failures)
    write_atomically(out / "report.html", "<!doctype html><meta charset='utf-8'><title>stylesync batch</title>"
                      "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:collapse}"
                      "td{border:1px solid #ccc;padding:2px 8px}</style>"
                      f"<h1>stylesync batch</h1><p>{text.splitlines()[2]}</p><table>{rows}</table>"
                      + (f"<h2>Failed</h2><ul>{fails}</ul>" if fails else ""))
    return summary


def print_progress(counts: BatchCounts) -> None:
    """A progress line on stderr, rewritten in place on a terminal."""
    end = "\r" if sys.stderr.isatty() else "\n"
    print(counts.line(), end=end, file=sys.stderr, flush=True)

"""One job of a batch: one clip through the whole pipeline, headless, as fast as possible.

The job returns what it produced (the session file's text, the metrics, the BVH text, the MP4's bytes) rather than
writing it: the driver writes it, so no result depends on a worker's disk. An input the pipeline refuses gives a
failed result with its one-line error, never an exception.
"""

from __future__ import annotations

import dataclasses
import logging
import tempfile
import traceback
from pathlib import Path

from stylesync.batch.clips import BatchSettings, Job
from stylesync.config import ControlConfig, OperatorConfig, SessionConfig
from stylesync.errors import StylesyncError

# metrics that measure the machine rather than the motion (they differ from run to run)
TIMING_FIELDS = ("realtime_factor", "control_tick_ms", "input_latency_ms")


def run_job(job: Job, settings: BatchSettings) -> dict:
    """``{"key", "name", "clip", "seed", "status": "ok" | "failed", "error", "metrics", "session", "bvh", "mp4"}``."""
    logging.disable(logging.WARNING)
    out = {"key": job.key, "name": job.name, "clip": str(job.clip), "seed": job.seed, "group": job.group,
           "status": "failed", "error": "", "metrics": None, "session": None, "bvh": None, "mp4": None}
    try:
        out.update(_run(job, settings))
        out["status"] = "ok"
    except StylesyncError as exc:
        out["error"] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    except (MemoryError, KeyboardInterrupt):
        raise
    except Exception as exc:  # noqa: BLE001 - a job never takes the batch down; the error is its result
        last = traceback.extract_tb(exc.__traceback__)[-1]
        out["error"] = f"internal error: {type(exc).__name__}: {exc} ({Path(last.filename).name}:{last.lineno})"
    return out


def _run(job: Job, settings: BatchSettings) -> dict:
    from stylesync.export.replay import export_bvh, export_mp4
    from stylesync.export.session_file import SessionRecorder, read_session
    from stylesync.metrics.summary import summarize
    from stylesync.session import Session
    from stylesync.sources.registry import open_source

    opened = open_source(job.spec, sensor=settings.sensor, seed=job.seed, duration_s=settings.duration_s)
    length = float(opened.duration_s or 0.0)
    if settings.duration_s is not None:
        length = min(length, settings.duration_s)
    if length <= 0.0:
        opened.source.close()
        raise StylesyncError(f"{job.clip}: the recording has no duration")
    base = SessionConfig()
    cfg = SessionConfig(duration_s=length, seed=job.seed, operator=OperatorConfig(),
                        clocks=dataclasses.replace(base.clocks, mocap_hz=opened.mocap_hz),
                        control=ControlConfig(lipm_time_sync=settings.lipm_time_sync))
    with tempfile.TemporaryDirectory(prefix="stylesync-job-") as tmp:
        record = Path(tmp) / "session.jsonl"
        session = Session(cfg, opened.source)
        session.prefetch_operator = False  # one process per job: the batch's workers are its parallelism
        recorder = SessionRecorder(record, cfg, session, deferred=True)
        session.on_tick = recorder.tick
        metrics = None
        try:
            result = session.run()
            metrics = summarize(result) | {"source": job.spec, "sensor": opened.sensor, "clip": str(job.clip),
                                           **opened.extras}
        finally:
            opened.source.close()
            recorder.close(metrics)
            session.release_engine()
        produced: dict = {"metrics": metrics, "session": record.read_text(encoding="utf-8")}
        if settings.export_bvh or settings.export_mp4:
            recorded = read_session(record)
            if settings.export_bvh and recorded.ticks:
                export_bvh(recorded, Path(tmp) / "motion.bvh")
                produced["bvh"] = (Path(tmp) / "motion.bvh").read_text(encoding="utf-8")
            if settings.export_mp4 and recorded.ticks:
                export_mp4(recorded, Path(tmp) / "motion.mp4")
                produced["mp4"] = (Path(tmp) / "motion.mp4").read_bytes()
    return produced

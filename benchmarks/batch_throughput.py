"""Batch throughput and a worker's memory over many clips.

    python benchmarks/batch_throughput.py --clips 16 --duration 6 --memory-clips 100

1. Throughput: the same clips (pybullet_data's humanoid3d set, each --duration simulated seconds, seed 0) through
   ``stylesync batch``'s Ray executor on a local Ray of 1 CPU and of one CPU per core, in one run; prints clips
   per minute for each (Ray's start timed apart) and their ratio.
2. Memory: --memory-clips jobs one after another through one worker process (the job a Ray worker runs), printing
   its resident memory after the first 5 jobs and after the last, and the growth.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import pybullet_data
import ray

from stylesync.batch import runner
from stylesync.batch.clips import BatchSettings, find_clips, jobs_for
from stylesync.batch.job import run_job


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clips", type=int, default=16)
    ap.add_argument("--duration", type=float, default=6.0)
    ap.add_argument("--memory-clips", type=int, default=100)
    args = ap.parse_args()
    motions = sorted((Path(pybullet_data.getDataPath()) / "data" / "motions").glob("humanoid3d_*.txt"))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "clips"
        folder.mkdir()
        for k in range(args.clips):
            src = motions[k % len(motions)]
            (folder / f"{k:03d}_{src.name}").write_bytes(src.read_bytes())
        settings = BatchSettings(duration_s=args.duration, export_bvh=False)
        jobs = jobs_for(find_clips(str(folder)), settings)
        rates = {}
        for workers in (1, os.cpu_count() or 1):
            t0 = time.perf_counter()
            ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, configure_logging=False)
            t1 = time.perf_counter()
            counts = runner.run_batch(jobs, settings, Path(tmp) / f"out{workers}", executor="ray")
            wall = time.perf_counter() - t1
            ray.shutdown()
            rates[workers] = 60.0 * counts.done / wall
            print(f"{workers} worker(s): {counts.done} clips of {args.duration:g} s in {wall:.1f} s: "
                  f"{rates[workers]:.1f} clips/min (Ray started in {t1 - t0:.1f} s before)")
        many = max(rates)
        print(f"ratio {many} workers / 1 worker: {rates[many] / rates[1]:.2f}")
        settings = BatchSettings(duration_s=0.5, export_bvh=True)
        mem_jobs = jobs_for(find_clips(str(folder)), settings)
        before = None
        for k in range(args.memory_clips):
            result = run_job(mem_jobs[k % len(mem_jobs)], settings)
            assert result["status"] == "ok", result["error"]
            if k == 4:
                before = rss_mb()
        after = rss_mb()
        print(f"one worker, {args.memory_clips} jobs of 0.5 s with BVH export: resident memory {before:.0f} MB "
              f"after 5, {after:.0f} MB after {args.memory_clips}: growth {after - before:+.1f} MB")


if __name__ == "__main__":
    main()

"""stylesync batch: results identical to runs of each clip alone, a node lost mid-batch, an interrupted batch
resumed without running a clip twice, failures recorded."""

from __future__ import annotations

import json
import shutil
import threading
from pathlib import Path

import pybullet_data
import pytest

from stylesync.batch import runner
from stylesync.batch.clips import BatchSettings, find_clips, jobs_for
from stylesync.batch.job import TIMING_FIELDS, run_job
from stylesync.cli import main as cli_main

MOCAP = Path(__file__).resolve().parents[2] / "shared" / "mocap"
MOTIONS = Path(pybullet_data.getDataPath()) / "data" / "motions"
SETTINGS = BatchSettings(seeds=(0,), duration_s=1.0)


@pytest.fixture
def clips(tmp_path) -> Path:
    folder = tmp_path / "clips"
    (folder / "dm").mkdir(parents=True)
    shutil.copy(MOTIONS / "humanoid3d_walk.txt", folder / "dm" / "walk.txt")
    shutil.copy(MOTIONS / "humanoid3d_walk.txt", folder / "dm" / "walk_copy.txt")
    shutil.copy(MOTIONS / "humanoid3d_run.txt", folder / "dm" / "run.txt")
    (folder / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    cmu = MOCAP / "cmu" / "02_01.bvh"
    if cmu.exists():
        shutil.copy(cmu, folder / "02_01.bvh")
    return folder


def _comparable(result_dir: Path) -> tuple[list[str], dict]:
    lines = (result_dir / "session.jsonl").read_text().splitlines()
    metrics = json.loads((result_dir / "metrics.json").read_text())
    assert json.loads(lines[-1])["metrics"]["fell"] == metrics["fell"]
    return lines[:-1], {k: v for k, v in metrics.items() if k not in TIMING_FIELDS}


def test_clips_are_found_in_folders_globs_and_lists_and_keyed_by_content(clips, tmp_path):
    found = find_clips(str(clips))
    assert {p.name for p in found} >= {"walk.txt", "walk_copy.txt", "run.txt", "broken.bvh"}
    assert find_clips(str(clips / "dm" / "w*.txt")) == sorted([clips / "dm" / "walk.txt",
                                                                 clips / "dm" / "walk_copy.txt"])
    listing = tmp_path / "some.list"
    listing.write_text("# two clips\nclips/dm/walk.txt\n\nclips/broken.bvh\n")
    assert [p.name for p in find_clips(str(listing))] == ["broken.bvh", "walk.txt"]
    jobs = jobs_for(find_clips(str(clips / "dm")), BatchSettings(seeds=(0, 1)))
    assert len(jobs) == 6 and len({j.key for j in jobs}) == 4  # a clip's copy has its keys (its own folder)
    assert len({j.name for j in jobs}) == 6
    other = jobs_for(find_clips(str(clips / "dm")), BatchSettings(seeds=(0, 1), sensor="none"))
    assert not {j.key for j in jobs} & {j.key for j in other}  # other settings, other jobs
    assert cli_main(["batch", str(tmp_path / "nothing"), "--out", str(tmp_path / "o")]) == 2


def test_a_ray_batch_gives_what_each_clip_gives_alone(clips, tmp_path, monkeypatch):
    """... in a Ray instance of its own: a cluster address left in the environment (or a stale
    /tmp/ray/ray_current_cluster of a cluster gone) is not joined."""
    pytest.importorskip("ray")
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:6390")  # no cluster there
    jobs = jobs_for(find_clips(str(clips)), SETTINGS)
    out = tmp_path / "out"
    counts = runner.run_batch(jobs, SETTINGS, out, executor="ray", workers=2)
    assert counts.failed == 1 and counts.done == len(jobs) - 1
    broken = json.loads((out / "clips" / next(j.name for j in jobs if j.clip.name == "broken.bvh")
                         / "result.json").read_text())
    assert broken["status"] == "failed" and "BVH" in broken["error"] and "\n" not in broken["error"]
    for job in jobs:
        if job.clip.name == "broken.bvh":
            continue
        alone = run_job(job, SETTINGS)
        assert alone["status"] == "ok"
        ref = tmp_path / "alone" / "clips" / job.name
        runner.write_result(tmp_path / "alone", alone)
        assert _comparable(out / "clips" / job.name) == _comparable(ref)
        assert (out / "clips" / job.name / "motion.bvh").read_text() == (ref / "motion.bvh").read_text()
    summary = json.loads((out / "batch.json").read_text())
    assert summary["with_result"] == len(jobs) and (out / "report.html").exists()
    assert "broken" in (out / "batch.md").read_text()


def test_an_interrupted_batch_resumes_without_running_a_clip_twice(clips, tmp_path, monkeypatch):
    jobs = jobs_for(find_clips(str(clips / "dm")), BatchSettings(seeds=(0, 1), duration_s=0.5))
    ran: list[str] = []

    def counted(job, settings):
        ran.append(job.name)
        return run_job(job, settings)

    monkeypatch.setattr(runner, "run_job", counted)

    def interrupt_after_first(counts):
        if counts.done == 1:
            raise KeyboardInterrupt

    out = tmp_path / "out"
    settings = BatchSettings(seeds=(0, 1), duration_s=0.5)
    with pytest.raises(KeyboardInterrupt):
        runner.run_batch(jobs, settings, out, executor="inline", progress=interrupt_after_first)
    assert len(ran) == 1 and json.loads((out / "batch.json").read_text())["with_result"] == 1
    counts = runner.run_batch(jobs, settings, out, executor="inline")
    assert counts.skipped == 1 and counts.done == len(jobs) - 1
    assert sorted(ran) == sorted(j.name for j in jobs)  # each job once over the two runs


def test_a_node_lost_during_a_ray_batch_leaves_every_clip_with_a_result(clips, tmp_path):
    ray = pytest.importorskip("ray")
    from ray.cluster_utils import Cluster

    settings = BatchSettings(seeds=(0, 1), duration_s=1.5)
    jobs = jobs_for(find_clips(str(clips / "dm")), settings)
    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    worker_node = cluster.add_node(num_cpus=1)
    ray.init(address=cluster.address, include_dashboard=False, log_to_driver=False)
    killed = threading.Event()

    def kill_when_first_is_done(counts):
        if counts.done >= 1 and not killed.is_set():
            killed.set()
            cluster.remove_node(worker_node, allow_graceful=False)

    try:
        counts = runner.run_batch(jobs, settings, tmp_path / "out", executor="ray", max_retries=3,
                                  progress=kill_when_first_is_done)
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert killed.is_set()
    print(f"node lost: {counts.retried} job(s) submitted again")
    assert counts.done == len(jobs) and counts.failed == 0
    for job in jobs:
        assert json.loads((tmp_path / "out" / "clips" / job.name / "result.json").read_text())["status"] == "ok"

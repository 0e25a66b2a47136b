"""The speed benchmark's second baseline (benchmarks/bench_pipeline.py): a pipeline run's world-changing engine calls,
replayed on a new engine without the controller, give the run's own trajectory, bit for bit."""

import importlib.util
import logging
from pathlib import Path

import numpy as np

from stylesync.config import OperatorConfig, SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_pipeline.py"


def _bench_module():
    spec = importlib.util.spec_from_file_location("bench_pipeline", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_runs_engine_calls_replayed_end_where_the_run_did():
    logging.getLogger("stylesync").setLevel(logging.ERROR)
    bench = _bench_module()
    cfg = SessionConfig(duration_s=1.5, seed=0, operator=OperatorConfig(clip="walk"))
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    calls = bench._record_world_calls(session.backend)
    run = session.run()
    end = session.backend.read_state(run.sim_duration_s)
    assert not run.fell
    names = [name for name, _ in calls]
    # the start (resets), then a torque and a step per physics step of the run
    assert names[0] == "reset" and names.count("step") == len(run.stage_ms["physics"]) == 900
    assert names.count("apply_torques") == names.count("step")
    rtf, root = bench.replayed_physics_rtf(cfg, calls, run.sim_duration_s)
    assert rtf > 0.0
    np.testing.assert_array_equal(root, end.root_pos_world)
    # without the recorded torques the body goes elsewhere: the check can fail
    idle = [(name, args) for name, args in calls if name != "apply_torques"]
    _, idle_root = bench.replayed_physics_rtf(cfg, idle, run.sim_duration_s)
    assert float(np.linalg.norm(idle_root - end.root_pos_world)) > 0.05
    session.release_engine()

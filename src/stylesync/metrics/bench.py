"""``stylesync bench``: stylesync against the baselines a user would otherwise pick, over a fixed clip suite, in
one run.

Controllers (same operator stream, same retargeted reference, same engine and gains):

* ``stylesync``: the whole controller of Sec. 5.4 and 6;
* ``plain-pd``: PD tracking (Eq. 13, Table 3 gains, implicit) of the retargeted reference with no balance control
  at all: no gravity compensation, no COM or root virtual control, no IPM/LIPM compensation, no stance-hip blend
  (the DeepMimic-style tracker without a learned policy). It runs on the Jacobian-transpose controller
  (controller.py), the realisation in which each of those parts can be switched off;
* ``no-compensation``: stylesync without the model-based compensation: the LIPM time sync (Eq. 21-23) off. (The
  IPM ankle torque of Eq. 20 has no separate term in the default controller: its ground-force plan places the
  centre of pressure.)

The suite is every humanoid3d clip of pybullet_data played by the built-in operator, plus the BVH files of
``../shared/mocap/cmu`` when present. The physics-only realtime factor of the same machine, measured in the same
run, is printed beside them: the engine stepping the character with zero torques, which falls and lies on the ground.
It is no ceiling: a lying body costs the engine about twice a walking one's contact work (135-160 against 65-70 µs a
step), and the engine steps the pipeline's own walk at about 26x real time (`benchmarks/bench_pipeline.py` replays a
run's engine calls).
"""

from __future__ import annotations

import dataclasses
import json
import platform
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from stylesync.config import ControlConfig, JacobianTransposeConfig, MotionConfig, OperatorConfig, SessionConfig
from stylesync.errors import SimulationError
from stylesync.metrics.summary import summarize
from stylesync.model.state import Torques
from stylesync.session import run_and_release
from stylesync.sim.factory import make_backend
from stylesync.sources.deepmimic_clip import builtin_clip_names
from stylesync.sources.registry import open_source

CONTROLLERS: dict[str, tuple[ControlConfig, MotionConfig]] = {
    "stylesync": (ControlConfig(), MotionConfig()),
    "plain-pd": (ControlConfig(balance="jacobian_transpose", lipm_time_sync=False,
                               jacobian_transpose=JacobianTransposeConfig(
                                   gravity_compensation=False, com_virtual_force=False, root_virtual_torque=False,
                                   ipm_ankle_compensation=False)),
                 MotionConfig(stance_hip_weight_w0=1.0)),
    "no-compensation": (ControlConfig(lipm_time_sync=False), MotionConfig()),
}
COLUMNS = ("fall rate", "time to fall [s]", "MPJPE global [mm]", "MPJPE root-rel. [mm]",
           "MPJPE global / root-rel. before the termination [mm]", "skate [mm]", "jitter [m/s²]", "lag [s]",
           "realtime factor")


def physics_only_rtf(cfg: SessionConfig, sim_s: float) -> float:
    """Realtime factor of the engine alone: the same world and character stepped with zero torques (it falls and
    lies on the ground, where the engine's contact work is about twice a walking body's)."""
    backend = make_backend(cfg.world, cfg.clocks.physics_hz)
    backend.reset(np.array([0.0, 0.0, 0.9]), np.array([1.0, 0.0, 0.0, 0.0]))
    zero = Torques.zeros()
    n = int(sim_s * cfg.clocks.physics_hz)
    t0 = time.perf_counter()
    for _ in range(n):
        backend.apply_torques(zero)
        backend.step()
    wall = time.perf_counter() - t0
    backend.close()
    return sim_s / wall


def clip_suite(shared: Path | None) -> list[str]:
    """Source specs of the suite."""
    specs = [f"builtin:{c}" for c in builtin_clip_names()]
    if shared is not None and (shared / "mocap" / "cmu").is_dir():
        specs += [f"bvh:{p}" for p in sorted((shared / "mocap" / "cmu").glob("*.bvh"))]
    return specs


def _run(spec: str, name: str, duration_s: float, seed: int) -> dict:
    control, motion = CONTROLLERS[name]
    opened = open_source(spec, seed=seed, duration_s=duration_s)
    length = min(duration_s, float(opened.duration_s or duration_s))
    cfg = SessionConfig(duration_s=length, seed=seed, control=control, motion=motion,
                        clocks=dataclasses.replace(SessionConfig().clocks, mocap_hz=opened.mocap_hz),
                        operator=OperatorConfig())
    result = run_and_release(cfg, opened.source)
    m = summarize(result)
    uhc = m.get("uhc_fall_time_s")
    fall_t = min(x for x in (m["fall_time_s"], uhc) if x is not None) if (m["fell"] or uhc is not None) else None
    return {"source": spec, "controller": name, "fell": fall_t is not None, "time_to_fall_s": fall_t,
            "sim_duration_s": m["sim_duration_s"], "mpjpe_global_mm": m.get("mpjpe_global_mm"),
            "mpjpe_root_mm": m.get("mpjpe_root_mm"), "mpjpe_global_before_uhc_mm": m.get("mpjpe_global_before_uhc_mm"),
            "mpjpe_root_before_uhc_mm": m.get("mpjpe_root_before_uhc_mm"), "foot_skate_mm": m.get("foot_skate_mm"),
            "jitter_mps2": m.get("jitter_mps2"), "sync_lag_s": m.get("sync_lag_s"),
            "realtime_factor": m["realtime_factor"]}


def _mean(rows: list[dict], key: str) -> float | None:
    v = [r[key] for r in rows if r[key] is not None]
    return float(np.mean(v)) if v else None


def aggregate(rows: list[dict]) -> dict[str, dict]:
    out = {}
    for name in CONTROLLERS:
        rs = [r for r in rows if r["controller"] == name]
        if not rs:
            continue
        fell = [r for r in rs if r["fell"]]
        out[name] = {"runs": len(rs), "fall_rate": len(fell) / len(rs),
                     "time_to_fall_s": _mean(fell, "time_to_fall_s"),
                     **{k: _mean(rs, k) for k in ("mpjpe_global_mm", "mpjpe_root_mm", "mpjpe_global_before_uhc_mm",
                                                  "mpjpe_root_before_uhc_mm", "foot_skate_mm", "jitter_mps2",
                                                  "sync_lag_s", "realtime_factor")}}
    return out


def markdown_table(agg: dict[str, dict], physics_rtf: float, header: str) -> str:
    def f(v, fmt):
        return "–" if v is None else format(v, fmt)

    lines = [header, "", "| controller | " + " | ".join(COLUMNS) + " |", "|---" * (len(COLUMNS) + 1) + "|"]
    for name, a in agg.items():
        lines.append(f"| {name} | {a['fall_rate']:.0%} ({a['runs']} runs) | {f(a['time_to_fall_s'], '.2f')} | "
                     f"{f(a['mpjpe_global_mm'], '.0f')} | {f(a['mpjpe_root_mm'], '.0f')} | "
                     f"{f(a['mpjpe_global_before_uhc_mm'], '.0f')} / {f(a['mpjpe_root_before_uhc_mm'], '.0f')} | "
                     f"{f(a['foot_skate_mm'], '.2f')} | {f(a['jitter_mps2'], '.1f')} | {f(a['sync_lag_s'], '.3f')} | "
                     f"{f(a['realtime_factor'], '.2f')}x |")
    lines.append(f"| physics alone (the character fallen, zero torques) | | | | | | | | | {physics_rtf:.2f}x |")
    return "\n".join(lines)


def run_bench(out: Path, duration_s: float = 10.0, seed: int = 0, shared: Path | None = None,
              progress=print, executor: str = "inline", workers: int | None = None) -> dict:
    """The suite on the batch runner's executors (parallel.py). By default one run after another in this process:
    the realtime factors are then comparable with the physics-alone figure measured alone; runs in parallel
    (``executor`` "processes" or "ray") share the cores and their realtime factors say less."""
    from stylesync.parallel import execute_all

    out.mkdir(parents=True, exist_ok=True)
    specs = clip_suite(shared)
    physics = physics_only_rtf(SessionConfig(), 10.0)
    items = [(spec, name, duration_s, seed) for spec in specs for name in CONTROLLERS]

    def show(k: int, row: object, note: str) -> None:
        if not isinstance(row, dict):
            raise SimulationError(f"bench: {items[k][0]} with {items[k][1]} did not run ({note})")
        status = f"fell at {row['time_to_fall_s']:.2f} s" if row["fell"] else "no fall"
        progress(f"{row['source']:<40} {row['controller']:<16} {status:<16} MPJPE {row['mpjpe_global_mm']} mm")

    rows = [row for row, _ in execute_all(_run, items, executor, workers, on_result=show) if isinstance(row, dict)]
    agg = aggregate(rows)
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    machine = f"{platform.machine()}, {platform.processor() or 'cpu'}, Python {platform.python_version()}"
    header = (f"stylesync bench, {stamp}, {len(specs)} clips x {len(CONTROLLERS)} controllers, "
              f"{duration_s:.0f} s each (seed {seed}); {machine}")
    table = markdown_table(agg, physics, header)
    report = {"date": stamp, "machine": machine, "duration_s": duration_s, "seed": seed, "clips": specs,
              "physics_only_realtime_factor": physics, "aggregate": agg, "runs": rows}
    (out / "bench.json").write_text(json.dumps(report, indent=2))
    (out / "bench.md").write_text(table + "\n")
    return report | {"table": table}

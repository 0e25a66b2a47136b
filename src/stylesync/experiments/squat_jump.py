"""Experiment ``squat-jump`` (Sec. 7.4.5, Fig. 16): a squat and a jump by operators of three body sizes; the
character must follow and stand firmly back in double stance (DS) without a fall.

* squat: scripted on the human model (scripted_operator.py; no squat clip is among our inputs): the pelvis goes
  down by ``SQUAT_DEPTH`` of the hip height over 1 s, holds 0.5 s and comes back up over 1 s, feet planted;
* jump: the recorded ``humanoid3d_jump`` clip of pybullet_data, played by the built-in operator.

Operators: statures 1.55, 1.75 and 1.95 m, masses scaled from the Table 2 human (75.8 kg at 1.75 m) by stature
squared. The claim checked: every run ends in DS with no fall. Exit status 0 only when it holds.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stylesync.config import OperatorConfig, SessionConfig  # noqa: E402
from stylesync.experiments.common import run_session  # noqa: E402
from stylesync.experiments.scripted_operator import pose_frame, standing_ankles  # noqa: E402
from stylesync.metrics.plots import save_figure  # noqa: E402
from stylesync.metrics.summary import summarize  # noqa: E402
from stylesync.motion.stance_fsm import Stance  # noqa: E402
from stylesync.processing.interpolation import smooth_step  # noqa: E402
from stylesync.session import STANCE_CODE, Session  # noqa: E402
from stylesync.sources.builtin_operator import builtin_operator, sensed  # noqa: E402
from stylesync.sources.deepmimic_clip import DeepMimicClip  # noqa: E402
from stylesync.sources.human_model import TABLE2_HUMAN_TOTAL_KG, HumanModel  # noqa: E402

STATURES_M = (1.55, 1.75, 1.95)
SQUAT_START_S = 1.5
SQUAT_DEPTH = 0.25  # fraction of the hip height the pelvis goes down
SQUAT_DOWN_S, SQUAT_HOLD_S, SQUAT_UP_S = 1.0, 0.5, 1.0
SETTLE_S = 2.0  # simulated after the motion, to see the character stand [s]
JUMP_CLIP = "jump"


def operator_of(stature_m: float, clip: str) -> OperatorConfig:
    return OperatorConfig(clip=clip, height_m=stature_m, mass_kg=TABLE2_HUMAN_TOTAL_KG * (stature_m / 1.75) ** 2)


def squat_performer(human: HumanModel):
    ankles = standing_ankles(human)
    hip_h = human.hip_height_m - 0.01

    def frame_at(t_s: float):
        u = t_s - SQUAT_START_S
        down = smooth_step(u / SQUAT_DOWN_S) - smooth_step((u - SQUAT_DOWN_S - SQUAT_HOLD_S) / SQUAT_UP_S)
        pelvis = np.array([0.0, 0.0, hip_h * (1.0 - SQUAT_DEPTH * down)])
        return pose_frame(human, t_s, pelvis, ankles)

    return frame_at


def run_one(task: str, stature_m: float, seed: int):
    if task == "squat":
        op = operator_of(stature_m, "squat")
        duration = SQUAT_START_S + SQUAT_DOWN_S + SQUAT_HOLD_S + SQUAT_UP_S + SETTLE_S
        cfg = SessionConfig(duration_s=duration, seed=seed, operator=op)
        human = HumanModel(op.height_m, op.mass_kg)
        source = sensed(squat_performer(human), op, cfg.clocks, duration + 1.0, seed, "squat")
    else:
        op = operator_of(stature_m, JUMP_CLIP)
        duration = op.standing_lead_in_s + DeepMimicClip.builtin(JUMP_CLIP).duration_s + SETTLE_S
        cfg = SessionConfig(duration_s=duration, seed=seed, operator=op)
        source, _ = builtin_operator(op, cfg.clocks, duration + 1.0, seed)
    return run_session(Session(cfg, source))


def run(out: Path, duration_s: float = 0.0, seed: int = 0) -> tuple[bool, dict]:
    """``duration_s`` is unused (each task fixes its own)."""
    out.mkdir(parents=True, exist_ok=True)
    runs: dict[str, dict] = {}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, task in zip(axes, ("squat", "jump"), strict=True):
        for stature in STATURES_M:
            r = run_one(task, stature, seed)
            m = summarize(r)
            final = r.log.array("char_state")[-1] if len(r.log.array("char_state")) else np.nan
            ends_ds = bool(not r.fell and final == STANCE_CODE[Stance.DS])
            runs[f"{task}@{stature:.2f}m"] = {"task": task, "stature_m": stature, "fell": r.fell,
                                             "fall_time_s": r.fall_time_s, "ends_in_ds": ends_ds,
                                             "mpjpe_root_mm": m.get("mpjpe_root_mm"),
                                             "com_error_m": m["com_error_m"]}
            ax.plot(r.log.array("t"), r.log.array("root_z"), label=f"{stature:.2f} m" + (" (fell)" if r.fell else ""))
        ax.set_title(f"{task}: pelvis height over time (Fig. 16)")
        ax.set_xlabel("t [s]")
        ax.legend()
    axes[0].set_ylabel("pelvis height [m]")
    save_figure(fig, out / "fig16_squat_jump.png")
    holds = all(v["ends_in_ds"] for v in runs.values())
    summary = {"experiment": "squat-jump", "claim_holds": holds, "statures_m": STATURES_M, "runs": runs}
    (out / "metrics.json").write_text(json.dumps(summary, indent=2))
    return holds, summary

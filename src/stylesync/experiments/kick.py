"""Experiment ``kick`` (Sec. 7.4.4, Fig. 15): reach a football and kick it.

Two runs, both on recorded operators of pybullet_data played by the built-in operator:
* ``walk-to-ball``: the walk clip with the ball on the ground ``WALK_BALL_AHEAD_M`` ahead of the character's
  start; reached = a character foot within ``REACH_M`` of the ball;
* ``kick``: the kick clip, with the ball where the operator's right ankle is at its fastest, scaled to the
  character (h_C / h_H, Eq. 9) about the starting pelvis.

Kicked = the ball moved more than ``KICKED_M``. The claim checked (the paper's: the character reaches the ball
and kicks it, keeping its balance): the walk reaches the ball and the kick moves it, both with no fall. The walk
clip has no kick in it: whether its steps happen to push the ball is recorded, not required. Exit status 0 only
when it holds.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stylesync import rotations as rot  # noqa: E402
from stylesync.config import OperatorConfig, SessionConfig  # noqa: E402
from stylesync.experiments.common import run_session  # noqa: E402
from stylesync.metrics.plots import plan_view, save_figure  # noqa: E402
from stylesync.model.character import SHANK_LENGTH_M, THIGH_LENGTH_M  # noqa: E402
from stylesync.session import Session  # noqa: E402
from stylesync.sources.builtin_operator import builtin_operator  # noqa: E402
from stylesync.sources.deepmimic_clip import DeepMimicClip  # noqa: E402
from stylesync.sources.frame import JOINT_INDEX  # noqa: E402

BALL_RADIUS_M = 0.11
WALK_BALL_AHEAD_M = 1.5
REACH_M = 0.35  # a foot's ankle this close to the ball's centre (horizontally) counts as reached [m]
KICKED_M = 0.2
AFTER_S = 2.0  # simulated after the clip [s]


def kick_ball_position(performer, op: OperatorConfig) -> np.ndarray:
    """Where the scaled operator's right ankle is when it moves fastest, on the ground, one ball radius ahead
    (about the operator's starting pelvis, where the character is stood up)."""
    clip = performer.clip
    times = np.arange(op.standing_lead_in_s, op.standing_lead_in_s + clip.duration_s, 1 / 60)
    frames = [performer.frame_at(t) for t in times]
    ankle = np.array([f.joint_pos_world[JOINT_INDEX["ANKLE_RIGHT"]] for f in frames])
    speed = np.linalg.norm(np.diff(ankle[:, :2], axis=0), axis=1)
    k = int(np.argmax(speed))
    direction = (ankle[k + 1, :2] - ankle[k, :2]) / max(speed[k], 1e-9)
    pelvis0 = frames[0].joint_pos_world[JOINT_INDEX["PELVIS"]]
    scale = (THIGH_LENGTH_M + SHANK_LENGTH_M) / (performer.human.thigh_m + performer.human.shank_m)
    xy = pelvis0[:2] + scale * (ankle[k, :2] - pelvis0[:2]) + BALL_RADIUS_M * direction
    return np.array([xy[0], xy[1], BALL_RADIUS_M])


def run_one(scenario: str, seed: int):
    clip = "walk" if scenario == "walk-to-ball" else "kick"
    op = OperatorConfig(clip=clip)
    clip_s = DeepMimicClip.builtin(clip).duration_s
    duration = min(op.standing_lead_in_s + clip_s * (3 if clip == "walk" else 1) + AFTER_S, 8.0)
    cfg = SessionConfig(duration_s=duration, seed=seed, operator=op)
    source, performer = builtin_operator(op, cfg.clocks, duration + 1.0, seed)
    session = Session(cfg, source)
    if clip == "walk":  # ahead of where the character is stood up: the operator's first pelvis, his heading
        first = performer.frame_at(0.0)
        pelvis0 = first.joint_pos_world[JOINT_INDEX["PELVIS"]]
        heading = rot.yaw_from_quat(first.joint_quat_wxyz[JOINT_INDEX["PELVIS"]])
        ahead = WALK_BALL_AHEAD_M * np.array([np.cos(heading), np.sin(heading)])
        ball0 = np.array([pelvis0[0] + ahead[0], pelvis0[1] + ahead[1], BALL_RADIUS_M])
    else:
        ball0 = kick_ball_position(performer, op)
    ball = session.backend.throw_ball(ball0, np.zeros(3), radius_m=BALL_RADIUS_M)
    track: list[np.ndarray] = []
    reach = [np.inf]

    def hook(state, ref) -> None:
        p = session.backend.body_position(ball)
        track.append(p)
        for side in ("left", "right"):
            a = state.link_origin_world[state.link(f"{side}_ankle")]
            reach[0] = min(reach[0], float(np.linalg.norm((a - p)[:2])))

    session.on_tick = hook
    result = run_session(session)
    path = np.array(track) if track else ball0[None, :]
    moved = float(np.linalg.norm((path[-1] - ball0)[:2]))
    return result, {"ball_start_m": ball0.tolist(), "closest_foot_m": reach[0], "reached": reach[0] <= REACH_M,
                    "ball_displacement_m": moved, "kicked": moved > KICKED_M, "fell": result.fell,
                    "fall_time_s": result.fall_time_s}, path


def claim_holds(scenarios: dict[str, dict]) -> bool:
    """The walk reaches the ball and the kick moves it, neither falling (``scenarios``: run_one's metrics by
    scenario name)."""
    walk, kick = scenarios["walk-to-ball"], scenarios["kick"]
    return bool(walk["reached"] and not walk["fell"] and kick["kicked"] and not kick["fell"])


def run(out: Path, duration_s: float = 0.0, seed: int = 0) -> tuple[bool, dict]:
    """``duration_s`` is unused (each scenario fixes its own)."""
    out.mkdir(parents=True, exist_ok=True)
    scenarios: dict[str, dict] = {}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, name in zip(axes, ("walk-to-ball", "kick"), strict=True):
        r, m, path = run_one(name, seed)
        scenarios[name] = m
        ax.plot(r.log.array("com_x"), r.log.array("com_y"), label="character COM")
        ax.plot(path[:, 0], path[:, 1], label="ball")
        ax.add_patch(plt.Circle(tuple(m["ball_start_m"][:2]), REACH_M, color="red", alpha=0.15,
                                label="reach area"))
        ax.set_title(f"{name}: " + ("fell" if m["fell"] else "no fall") + (", kicked" if m["kicked"] else ""))
        plan_view(ax)
    save_figure(fig, out / "fig15_kick.png")
    holds = claim_holds(scenarios)
    summary = {"experiment": "kick", "claim_holds": holds, "reach_m": REACH_M, "kicked_m": KICKED_M,
               "scenarios": scenarios}
    (out / "metrics.json").write_text(json.dumps(summary, indent=2))
    return holds, summary

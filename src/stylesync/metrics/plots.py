"""Figures of a run: COM with footsteps (Fig. 13), stance states (Fig. 11), style features, render strip."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from stylesync.session import SessionResult  # noqa: E402


def save_figure(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def plan_view(ax) -> None:
    """A top view of the floor [m], equal axes."""
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.axis("equal")
    ax.legend(fontsize=7)


def stance_axes(ax, log, character_offset: float = 0.0) -> None:
    """Operator and character stance states over time (Fig. 11)."""
    t = log.array("t")
    ax.step(t, log.array("op_state"), where="post", label="operator")
    ax.step(t, log.array("char_state") + character_offset, where="post", label="character")
    ax.set_yticks([0, 1, 2], ["LS", "DS", "RS"])


def write_plots(result: SessionResult, out: Path) -> list[Path]:
    lg = result.log
    t = lg.array("t")
    paths = []
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(lg.array("com_x"), lg.array("com_y"), label="character COM")
    s = lg.array("scale")
    ax.plot(lg.array("op_com_x") * s, lg.array("op_com_y") * s, "--", label="operator COM (scaled)")
    for side, c in (("l", "tab:blue"), ("r", "tab:red")):
        z = lg.array(f"a{side}_z")
        on = z < 0.075
        ax.scatter(lg.array(f"a{side}_x")[on], lg.array(f"a{side}_y")[on], s=4, c=c, alpha=0.3)
    plan_view(ax)
    ax.set_title("COM trajectory and footsteps")
    paths.append(save_figure(fig, out / "com_footsteps.png"))

    fig, ax = plt.subplots(figsize=(8, 3))
    stance_axes(ax, lg, character_offset=0.05)
    ax.set_xlabel("t [s]")
    ax.legend()
    ax.set_title("Stance states")
    paths.append(save_figure(fig, out / "stance_states.png"))

    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for ax, key, label in zip(axes, ("N_r_y", "T_r", "H"), ("N_r (y)", "T_r [rad]", "H [rad]"), strict=True):
        ax.plot(t, lg.array(f"op_{key}"), label="operator")
        ax.plot(t, lg.array(f"ch_{key}"), label="character")
        ax.set_ylabel(label)
    axes[0].legend()
    axes[-1].set_xlabel("t [s]")
    paths.append(save_figure(fig, out / "style_features.png"))
    return paths


def write_strip(frames: list[tuple[float, np.ndarray]], path: Path) -> Path | None:
    if not frames:
        return None
    import imageio.v3 as iio

    strip = np.concatenate([f for _, f in frames[:8]], axis=1)
    iio.imwrite(path, strip)
    return path

"""Small pieces every experiment uses: one closed session run, a floor-plan axis, saving a figure."""

from __future__ import annotations

from pathlib import Path

from stylesync.session import Session, SessionResult


def run_session(session: Session, stop_on_fall: bool = True) -> SessionResult:
    """Run a session to its end; its engine is closed afterwards."""
    session.stop_on_fall = stop_on_fall
    try:
        return session.run()
    finally:
        session.backend.close()


def plan_view(ax) -> None:
    """A top view of the floor [m], equal axes."""
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.axis("equal")
    ax.legend(fontsize=7)


def save_figure(fig, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)

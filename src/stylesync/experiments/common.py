"""What every experiment does with a session: run it to its end and close its engine."""

from __future__ import annotations

from stylesync.session import Session, SessionResult


def run_session(session: Session, stop_on_fall: bool = True) -> SessionResult:
    """Run a session to its end; its engine is closed afterwards."""
    session.stop_on_fall = stop_on_fall
    try:
        return session.run()
    finally:
        session.backend.close()

"""Realtime factor of the control loop with and without the web viewer and one browser connected (prints figures).

    python benchmarks/viewer_overhead.py [--duration 15] [--repeats 2] [--clip stand]

The loop runs as fast as possible (offline) so that any time the viewer takes from it shows in the realtime factor.
Runs alternate (without, with, without, with, ...) in this one process, and the medians are compared, so the ratio
holds on a noisy machine. The browser is headless Chromium driven by Playwright, on the same machine: its
software WebGL rendering competes for the same cores, as a local browser would.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from stylesync.config import VIEWER_DRAW_HZ, OperatorConfig, SessionConfig
from stylesync.session import Session
from stylesync.sources.builtin_operator import builtin_operator
from stylesync.viewer.attach import chain, open_viewer, session_hook


def run_once(cfg: SessionConfig, with_viewer: bool, browser, draw_hz: float,
             viewer_cpus: set[int] | None = None) -> tuple[float, int]:
    source, _ = builtin_operator(cfg.operator, cfg.clocks, cfg.duration_s + 1.0, cfg.seed)
    session = Session(cfg, source)
    # Both arms compute the operator side in the loop's process: a run with a viewer has a thread, and so never
    # forks it (prefetch.py). This measures the viewer's own cost; a run without a viewer is faster still.
    session.prefetch_operator = False
    viewer, page = None, None
    if with_viewer:
        viewer = open_viewer("web", session, draw_hz=draw_hz)
        if viewer_cpus:
            os.sched_setaffinity(viewer._proc.pid, viewer_cpus)
        session.on_tick = chain(session_hook(session, viewer, draw_hz))
        page = browser.new_page(viewport={"width": 1000, "height": 700})
        page.goto(viewer.url)
        page.get_by_text("Push (throw a ball at the chest)").wait_for(timeout=30000)
    result = session.run()
    frames = viewer.published if viewer is not None else 0
    if page is not None:
        page.close()
    if viewer is not None:
        viewer.close()
    session.backend.close()
    return result.sim_duration_s / result.wall_duration_s, frames


def _wrapper(command: list[str]) -> str:
    """An executable that runs ``command`` with the browser's arguments (Playwright takes one path)."""
    if len(command) == 1:
        return command[0]
    path = Path(tempfile.mkdtemp()) / "chromium-pinned"
    path.write_text("#!/bin/sh\nexec " + " ".join(command) + ' "$@"\n')
    path.chmod(0o755)
    return str(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=15.0)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--clip", default="stand")
    ap.add_argument("--draw-hz", type=float, default=VIEWER_DRAW_HZ, help="viewer drawing rate [Hz]")
    ap.add_argument("--pin", action="store_true",
                    help="pin the control loop to the first CPU, the viewer process and the browser to the others "
                         "(as on a machine whose browser renders on a GPU)")
    args = ap.parse_args()
    cpus = sorted(os.sched_getaffinity(0))
    browser_cpus: set[int] | None = None
    if args.pin and len(cpus) >= 2:
        os.sched_setaffinity(0, {cpus[0]})
        browser_cpus = set(cpus[1:])
    from playwright.sync_api import sync_playwright

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("needs headless Chromium (Debian package 'chromium')")
    cfg = SessionConfig(duration_s=args.duration, operator=OperatorConfig(clip=args.clip))
    without, with_ = [], []
    with sync_playwright() as p:
        pin = ["taskset", "-c", ",".join(map(str, browser_cpus))] if browser_cpus else []
        launch = [*pin, chromium]
        browser = p.chromium.launch(executable_path=_wrapper(launch),
                                    args=["--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader"])
        for _ in range(args.repeats):
            without.append(run_once(cfg, False, browser, args.draw_hz)[0])
            rtf, frames = run_once(cfg, True, browser, args.draw_hz, browser_cpus)
            with_.append(rtf)
            print(f"  without viewer {without[-1]:.2f}x, with viewer and a browser {rtf:.2f}x "
                  f"({frames} snapshots sent)")
        browser.close()
    a, b = statistics.median(without), statistics.median(with_)
    print(f"clip {args.clip}, {args.duration:.0f} s simulated per run, {args.repeats} runs each, viewer at "
          f"{args.draw_hz:.0f} Hz, {'loop and browser on separate CPUs' if browser_cpus else 'no CPU pinning'}")
    print(f"realtime factor without viewer (median): {a:.2f}x")
    print(f"realtime factor with viewer + browser:   {b:.2f}x")
    print(f"drop: {100 * (1 - b / a):.1f} %")


if __name__ == "__main__":
    main()

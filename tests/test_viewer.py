"""The web viewer, seen from a real browser (headless Chromium driven by Playwright), and its geometry helpers."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from stylesync.motion.stance_fsm import Stance
from stylesync.viewer.snapshot import Snapshot, support_polygon
from stylesync.viewer.web_viewer import free_port

ARTEFACTS = Path(os.environ.get("STYLESYNC_TEST_ARTEFACTS", "out/test-artifacts")) / "viewer"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _snap(feet_down: dict[str, bool]) -> Snapshot:
    z = np.zeros((15, 3))
    return Snapshot(0.0, np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros((12, 4)), z, np.tile([1.0, 0, 0, 0], (15, 1)),
                    np.zeros(3), feet_down, {"left": np.array([0.0, 0.1, 0.05]), "right": np.array([0.0, -0.1, 0.05])},
                    {"left": 0.0, "right": 0.0}, Stance.DS, Stance.DS, None, 0.8, {})


def test_support_polygon_spans_the_feet_on_the_ground():
    both = support_polygon(_snap({"left": True, "right": True}))
    # Two 17.7 x 9 cm soles 20 cm apart (centre to centre): hull 17.7 cm long, 29 cm wide.
    assert np.ptp(both[:, 0]) == pytest.approx(0.177, abs=1e-3)
    assert np.ptp(both[:, 1]) == pytest.approx(0.29, abs=1e-3)
    left = support_polygon(_snap({"left": True, "right": False}))
    assert len(left) == 4 and left[:, 1].min() == pytest.approx(0.055, abs=1e-3)
    assert len(support_polygon(_snap({"left": False, "right": False}))) == 0


def _region_change(a: Path, b: Path, box: tuple[int, int, int, int]) -> float:
    import imageio.v3 as iio

    x0, y0, x1, y1 = box
    ia = iio.imread(a)[y0:y1, x0:x1, :3].astype(float)
    ib = iio.imread(b)[y0:y1, x0:x1, :3].astype(float)
    return float(np.mean(np.abs(ia - ib) > 24))  # share of pixels that changed visibly


@pytest.mark.skipif(CHROMIUM is None, reason="needs headless Chromium (Debian package 'chromium')")
def test_browser_sees_the_character_move_and_pushes_it(tmp_path):
    playwright = pytest.importorskip("playwright.sync_api", reason="needs playwright (pip install playwright)")
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "stylesync.cli", "demo", "--clip", "walk", "--duration", "60", "--viewer", "web",
         "--viewer-port", str(port), "--out", str(tmp_path / "run")],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith("viewer: "):
                url = line.split()[1]
                break
            assert time.monotonic() < deadline, "the viewer address was not printed"
        else:
            pytest.fail("the run ended before printing the viewer address")
        assert url == f"http://127.0.0.1:{port}"
        with playwright.sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--use-gl=swiftshader",
                                                                        "--enable-unsafe-swiftshader"])
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            page.goto(url)
            page.get_by_text("Push (throw a ball at the chest)").wait_for(timeout=30000)
            page.get_by_text("Operator skeleton").click()  # only the character in the scene
            page.wait_for_timeout(1500)
            shots = [ARTEFACTS / "1-before.png", ARTEFACTS / "2-later.png", ARTEFACTS / "3-after-push.png"]
            page.screenshot(path=str(shots[0]))
            page.wait_for_timeout(1500)
            page.screenshot(path=str(shots[1]))
            page.get_by_text("Push (throw a ball at the chest)").click()
            page.get_by_text(re.compile(r"balls thrown: 1")).wait_for(timeout=10000)
            page.wait_for_timeout(800)
            page.screenshot(path=str(shots[2]))
            browser.close()
        character_region = (100, 100, 640, 700)  # the 3D view left of the control panel, around the camera target
        assert _region_change(shots[0], shots[1], character_region) > 0.002
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _port_open(port: int) -> bool:
    import socket

    with socket.socket() as s:
        s.settimeout(0.5)
        return s.connect_ex(("127.0.0.1", port)) == 0


def _start_viewer_demo(tmp_path: Path) -> tuple[subprocess.Popen, int]:
    pytest.importorskip("viser", reason="needs viser (pip install -e '.[viewer]')")
    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "stylesync.cli", "demo", "--duration", "60", "--viewer", "web", "--viewer-port",
         str(port), "--out", str(tmp_path / "run")], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.startswith("viewer: "):
            break
    else:
        pytest.fail("the run ended before printing the viewer address")
    assert _port_open(port)
    return proc, port


@pytest.mark.parametrize("kill", [False, True], ids=["terminated", "killed"])
def test_viewer_process_ends_with_its_session(tmp_path, kill):
    # Terminated (SIGTERM), the session ends as with Ctrl-C and closes its viewer; killed (SIGKILL), it cannot,
    # and the orphaned viewer process must notice and end on its own, freeing its port.
    proc, port = _start_viewer_demo(tmp_path)
    (proc.kill if kill else proc.terminate)()
    code = proc.wait(timeout=20)
    assert code == (-9 if kill else 130)
    deadline = time.monotonic() + 10
    while _port_open(port) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _port_open(port), "the viewer process outlived its session"

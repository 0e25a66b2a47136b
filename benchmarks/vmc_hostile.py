"""A live VMC run under hostile traffic: ``stylesync run --source vmc://127.0.0.1:PORT`` in its own process, fed by a
sender that streams a standing operator at 60 Hz, a bundle time-tagged an hour ahead, --garbage random datagrams
and a burst of --burst frames sent as fast as the socket takes them; then Ctrl-C (SIGINT).

    python benchmarks/vmc_hostile.py --garbage 10000 --burst 5000

Prints the time from SIGINT to the run's exit, its exit code, whether its stderr holds a traceback, and the
rejections by reason from its metrics.json.
"""

from __future__ import annotations

import argparse
import json
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from stylesync.sources.human_model import HumanModel
from stylesync.sources.vmc import VmcSender, osc_bundle
from stylesync.viewer.web_viewer import free_port


def bundle(messages, timetag: float | None = None) -> bytes:
    return osc_bundle(messages, timetag).dgram


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--garbage", type=int, default=10_000)
    ap.add_argument("--burst", type=int, default=5_000)
    args = ap.parse_args()
    port = free_port()
    h = HumanModel()
    builder = VmcSender("127.0.0.1", 9)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        proc = subprocess.Popen([sys.executable, "-m", "stylesync.cli", "run", "--source", f"vmc://127.0.0.1:{port}",
                                 "--duration", "600", "--out", str(out)], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        addr = ("127.0.0.1", port)
        rng = np.random.default_rng(0)
        t0 = time.perf_counter()
        k = 0

        def standing(n: int) -> None:
            nonlocal k
            for _ in range(n):
                frame = h.frame_from_pose(k / 60, np.array([0.0, 0.0, h.hip_height_m]), {})
                sock.sendto(bundle(builder.messages(frame)), addr)
                k += 1
                time.sleep(1 / 60)

        standing(180)  # the run starts on these (3 s)
        good = bundle(builder.messages(h.frame_from_pose(0.0, np.array([0.0, 0.0, h.hip_height_m]), {})))
        sock.sendto(bundle(builder.messages(h.frame_from_pose(3.0, np.array([0.0, 0.0, h.hip_height_m]), {})),
                           time.time() + 3600.0), addr)
        for g in range(args.garbage):
            sock.sendto(rng.bytes(int(rng.integers(1, 300))), addr)
            if g % 50 == 49:
                time.sleep(0.005)
        standing(60)
        for b in range(args.burst):
            sock.sendto(good, addr)
            if b % 50 == 49:
                time.sleep(0.005)
        standing(120)
        sent_s = time.perf_counter() - t0
        proc.send_signal(signal.SIGINT)
        t_int = time.perf_counter()
        try:
            stdout, stderr = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            stdout, stderr = proc.communicate()
        shutdown_s = time.perf_counter() - t_int
        metrics_path = out / "metrics.json"
        metrics = json.loads(metrics_path.read_text()) if metrics_path.exists() else None
        print(f"sent for {sent_s:.1f} s: {k} standing frames, 1 future-tagged bundle, {args.garbage} garbage "
              f"datagrams, a burst of {args.burst} frames")
        print(f"SIGINT -> exit in {shutdown_s:.2f} s, exit code {proc.returncode}, "
              f"traceback on stderr: {'Traceback' in stderr}")
        if metrics is None:
            print("metrics.json: not written")
        else:
            print(f"metrics.json: fell {metrics['fell']}, rejected {metrics['rejected_frames']}, "
                  f"by reason {metrics.get('rejections')}")
        print("stderr:", "\n".join(stderr.strip().splitlines()[-5:]))


if __name__ == "__main__":
    main()

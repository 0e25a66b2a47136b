"""VMC input latency: a separate process streams a standing operator at 60 Hz over VMC on 127.0.0.1; the session
runs paced to the wall clock and reports, for each frame, the time from its arrival on the socket to the first
control tick that uses it (goal: one control period, 7.5 ms)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

import numpy as np

from stylesync.config import SessionConfig
from stylesync.metrics.summary import summarize
from stylesync.session import Session
from stylesync.sources.vmc import VmcSource

SENDER = """
import time, numpy as np
from stylesync.sources.human_model import HumanModel
from stylesync.sources.vmc import VmcSender
h = HumanModel(); s = VmcSender('127.0.0.1', {port}); t0 = time.perf_counter()
for k in range(int(({duration} + 2) * 60)):
    s.send(h.frame_from_pose(k / 60, np.array([0.0, 0.0, h.hip_height_m]), {{}}))
    time.sleep(max(0.0, t0 + (k + 1) / 60 - time.perf_counter()))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--duration", type=float, default=10.0)
    args = ap.parse_args()
    source = VmcSource("127.0.0.1", 0)
    sender = subprocess.Popen([sys.executable, "-c", SENDER.format(port=source.port, duration=args.duration)])
    try:
        result = Session(SessionConfig(duration_s=args.duration, realtime=True), source).run()
    finally:
        sender.kill()
        source.close()
    m = summarize(result)
    lat = np.array(result.input_latency_ms)
    print(json.dumps({"frames": len(lat), "rejected": source.rejected_frames, "fell": m["fell"],
                      "latency_ms": {"p50": round(float(np.percentile(lat, 50)), 2),
                                     "p95": round(float(np.percentile(lat, 95)), 2),
                                     "max": round(float(lat.max()), 2)},
                      "within_7_5_ms": round(float(np.mean(lat <= 7.5)), 3),
                      "control_tick_ms": m["control_tick_ms"]}))


if __name__ == "__main__":
    main()

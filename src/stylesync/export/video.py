"""MP4 video of a session from the engine's software renderer (TinyRenderer), through imageio-ffmpeg.

The character is posed kinematically from the recorded states (no simulation), so a replay shows exactly what
was recorded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stylesync.errors import StylesyncError


def write_mp4(path: str | Path, frames_rgb: list[np.ndarray], fps: float) -> None:
    try:
        import imageio.v2 as imageio
    except ImportError:
        raise StylesyncError("MP4 export needs imageio-ffmpeg: pip install imageio-ffmpeg") from None
    try:
        with imageio.get_writer(str(path), fps=fps, codec="libx264", macro_block_size=8) as w:
            for f in frames_rgb:
                w.append_data(f)  # type: ignore[attr-defined]
    except (OSError, RuntimeError) as exc:
        raise StylesyncError(f"cannot write {path}: {exc}".splitlines()[0]) from None

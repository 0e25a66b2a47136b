import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stylesync.errors import SourceError
from stylesync.sources.deepmimic_clip import DeepMimicClip


@given(st.text(max_size=200))
@settings(max_examples=50, deadline=None)
def test_clip_parser_rejects_garbage_cleanly(tmp_path_factory, text):
    p = tmp_path_factory.mktemp("c") / "clip.txt"
    p.write_text(text)
    try:
        DeepMimicClip.load(p)
    except SourceError:
        pass


def test_clip_with_nan_rejected(tmp_path):
    frame = [0.03] + [0.0] * 43
    frame[8] = float("nan")
    p = tmp_path / "c.txt"
    p.write_text(json.dumps({"Loop": "none", "Frames": [frame, frame]}).replace("NaN", "NaN"))
    with pytest.raises(SourceError):
        DeepMimicClip.load(p)


def test_builtin_walk_loads_and_loops():
    clip = DeepMimicClip.builtin("walk")
    a, b = clip.pose_at(0.2), clip.pose_at(0.2 + clip.duration_s)
    assert np.linalg.norm((b.root_pos_world - a.root_pos_world)[:2]) > 0.5

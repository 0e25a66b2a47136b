"""The ground goes on under the character wherever it is: recordings far from their origin, long walks."""

import json

import numpy as np
import pybullet_data

from stylesync import rotations as rot
from stylesync.config import WorldConfig
from stylesync.model.character import STANDING_ROOT_HEIGHT_M
from stylesync.model.state import Torques
from stylesync.sim.factory import make_backend
from stylesync.sim.pybullet_backend import GROUND_TILE_M

FAR_XY_M = (2.5 * GROUND_TILE_M, -1.3 * GROUND_TILE_M)  # beyond the ground box's own 100 m half width


def test_a_character_far_from_the_origin_stands_on_the_ground():
    b = make_backend(WorldConfig(), 600.0)
    b.reset(np.array([*FAR_XY_M, STANDING_ROOT_HEIGHT_M + 0.003]), rot.IDENTITY_WXYZ)
    zero = Torques(np.zeros((len(b.read_state(0.0).joint_pos), 4)))
    pressed, lowest = False, np.inf
    for i in range(300):  # 0.5 s, limp: it sinks onto the ground and lies there
        s = b.read_state(i / 600)
        pressed |= all(s.feet_pressing().values())
        lowest = min(lowest, float(s.root_pos_world[2]))
        b.apply_torques(zero)
        b.step()
    b.close()
    assert pressed, "the feet never pressed a ground 250 m from the origin"
    assert lowest > 0.05, f"the pelvis went down to {lowest:.2f} m: no ground under it"


def _shifted_walk(tmp_path, dx_m: float, dz_m: float) -> str:
    """pybullet_data's humanoid3d walk (Y up) with its root moved by (dx, 0, dz), as a DeepMimic clip file."""
    with open(f"{pybullet_data.getDataPath()}/data/motions/humanoid3d_walk.txt") as f:
        clip = json.load(f)
    for frame in clip["Frames"]:
        frame[1] += dx_m
        frame[3] += dz_m
    path = tmp_path / f"walk_{dx_m:+.0f}_{dz_m:+.0f}.txt"
    path.write_text(json.dumps(clip))
    return f"deepmimic:{path}"


def test_a_recording_far_from_its_origin_runs_as_one_at_it(tmp_path):
    """The same walk recorded 300 m from the origin and at it: the same steps, no fall, the same imitation (the
    character starts where the operator stands, scaled: beyond the ground box's edge without the ground following)."""
    from stylesync.metrics.dev_suite import run_clip

    near = run_clip(_shifted_walk(tmp_path, 0.0, 0.0), 0, 4.0, "stylesync")
    far = run_clip(_shifted_walk(tmp_path, 300.0, -200.0), 0, 4.0, "stylesync")
    assert not near["fell"] and not far["fell"], (near["fall_reason"], far["fall_reason"])
    assert far["character_steps"] == near["character_steps"]
    assert abs(far["mpjpe_root_mm"] - near["mpjpe_root_mm"]) < 5.0

"""The viewer export: MuJoCo loads replay.xml and its keys hold the exported frames."""

from __future__ import annotations

import json

import mujoco
import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.sim.export import MAX_KEYS, export_replay
from avatarsim.sim.humanoid import humanoid_for


def test_replay_keys_are_the_exported_frames(tmp_path):
    motion = generate("walk", duration_s=1.0, fps=30.0, seed=3)
    humanoid = humanoid_for(motion)
    qpos = humanoid.body.qpos_from_motion(motion)
    paths = export_replay(humanoid, qpos, 30.0, tmp_path)
    replay = mujoco.MjModel.from_xml_path(str(paths[1]))
    info = json.loads(paths[3].read_text())
    assert replay.nkey == len(qpos) == len(info["key_frames"]) <= MAX_KEYS
    # MuJoCo writes XML numbers with 6 significant digits.
    np.testing.assert_allclose(replay.key_qpos, qpos, atol=1e-4 * np.abs(qpos).max())
    np.testing.assert_allclose(replay.key_time, np.arange(len(qpos)) / 30.0, atol=1e-6)
    assert mujoco.MjModel.from_xml_path(str(paths[0])).nkey == 0
    np.testing.assert_array_equal(np.load(paths[2]), qpos)
    assert not list(tmp_path.glob(".*.tmp"))

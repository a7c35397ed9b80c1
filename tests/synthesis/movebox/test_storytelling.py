"""The storytelling scene: actors staged at their marks, looped, the speaker's jaw moving,
and an MJCF scene MuJoCo loads with one keyframe per key time."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.face import LipSync
from avatarsim.synthesis.movebox.storytelling import Actor, drawn_bones, scene_spec, stage


@pytest.fixture(scope="module")
def staged():
    speech = LipSync(30.0, np.linspace(0, 1, 60), np.zeros(60))
    actors = [
        Actor(
            "talker", generate("wave", duration_s=1.5, fps=30.0, seed=0), (0.0, 0.0), 0.0, speech
        ),
        Actor("boxer", generate("box", duration_s=1.5, fps=30.0, seed=1), (0.5, 1.5), 0.5),
    ]
    return stage(actors, 2.0, np.random.default_rng(0))


def test_actors_stand_on_their_marks_for_the_whole_scene(staged):
    assert [m.n_frames for m in staged] == [61, 61]
    assert np.allclose(staged[1].root_pos[0, :2], [0.5, 1.5])
    jaw = staged[0].skeleton.index("Bip01 Jaw")
    assert not np.allclose(staged[0].local_rot[:, jaw], staged[0].local_rot[0, jaw])
    assert np.allclose(staged[1].local_rot[:, jaw], [1, 0, 0, 0])  # the boxer does not talk


def test_scene_loads_in_mujoco_with_its_keyframes(staged):
    spec = scene_spec(staged, key_fps=10.0)
    model = mujoco.MjModel.from_xml_string(spec.to_xml())
    assert model.nkey == 21  # 2 s at 10 keys/s, both ends
    assert model.nmocap == sum(len(drawn_bones(m)) for m in staged)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 10)
    mujoco.mj_forward(model, data)
    assert np.isfinite(data.xpos).all() and data.xpos[1:, 2].max() > 1.0


def test_a_scene_needs_actors():
    with pytest.raises(SynthesisError, match="at least one actor"):
        stage([], 1.0, np.random.default_rng(0))

"""ControllerPose as a registered method on a real clip of each source (CMU, Bandai
dataset-1 and dataset-2), rendered through the simulated devices, with the tiny model the
session trained: it runs on the VR stream's clock, finite, its head on the clip's head."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.formats.bvh import read_bvh
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, VRSetup
from avatarsim.render_cams.vr.noise import REALISTIC_NOISE
from avatarsim.scripts.controllerpose.recording import keypoint_recording
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.synthesis.base import on_clock
from avatarsim.synthesis.controllerpose.synthesizer import MODEL_ENV
from avatarsim.synthesis.methods import MethodInputs, build

CLIPS = {
    "cmu": "cmu/09_01.bvh",
    "bandai-1": "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh",
    "bandai-2": "bandai/dataset-2/data/dataset-2_wave-right-hand_youthful_001.bvh",
}
SECONDS = 1.0


@pytest.mark.mocap
@pytest.mark.parametrize("source", sorted(CLIPS))
def test_controllerpose_runs_on_a_real_clip(source, mocap_dir, cp_run, monkeypatch):
    """On the VR clock, finite, and the head where the headset says it is: its mean distance
    to the clip's own head is under 15 cm while the head travels up to 3.5 m (measured, seeds
    0-1: CMU run 8.6-9.4 cm, Bandai walk 2.7-3.0, Bandai wave 1.1-1.2)."""
    motion = read_bvh(mocap_dir / CLIPS[source])
    motion = motion[: int(SECONDS * motion.fps)]
    humanoid = humanoid_for(motion)
    stream = VRSetup(devices=HEADSET_AND_CONTROLLERS, noise=REALISTIC_NOISE).sample(
        humanoid.motion, seed=0
    )
    monkeypatch.setenv(MODEL_ENV, str(cp_run))
    inputs = MethodInputs(
        database_factory=list,
        user_height_m=standing_height(humanoid.motion),
        rig=humanoid.body.skeleton,
        fisheye=keypoint_recording(humanoid, 0),
    )
    output = build("controllerpose", inputs).run(stream)
    assert output.n_frames == on_clock(stream).n_samples
    assert np.isfinite(output.local_rot).all() and np.isfinite(output.root_pos).all()
    truth = humanoid.motion.sample(on_clock(stream).timestamps)
    head = [body17_positions(m)[:, INDEX["head"]] for m in (output, truth)]
    assert np.linalg.norm(head[0] - head[1], axis=-1).mean() < 0.15


def test_without_the_cameras_the_method_says_which_device_to_enable(monkeypatch):
    from avatarsim.avatar_models.generator import generate
    from avatarsim.synthesis.base import SynthesisError

    rig = generate("walk", duration_s=0.2, fps=30.0).skeleton
    inputs = MethodInputs(database_factory=list, user_height_m=1.75, rig=rig)
    with pytest.raises(SynthesisError, match=r"\[devices\] fisheye"):
        build("controllerpose", inputs)

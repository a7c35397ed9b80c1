"""The controller cameras' keypoints as ControllerPose reads them, from any humanoid."""

import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.controllerpose.recording import keypoint_recording
from avatarsim.sim.humanoid import humanoid_for


def test_keypoints_of_a_builtin_wave_are_on_a_30_hz_clock_and_seeded():
    # Regression: the scenario runner, the leaderboard and `eval controllerpose --mocap` called
    # this without the detector's seed after the dataset's detector noise landed (exit 3).
    humanoid = humanoid_for(generate("wave", duration_s=0.5, fps=30.0))
    first = keypoint_recording(humanoid, 0)
    again = keypoint_recording(humanoid, 0)
    other = keypoint_recording(humanoid, 1)
    n = first.time.size
    assert first.uv.shape == (n, 4, 17, 2) and first.conf.shape == (n, 4, 17)
    np.testing.assert_allclose(np.diff(first.time), 1 / 30.0)
    np.testing.assert_array_equal(first.uv, again.uv)
    assert not np.array_equal(first.uv, other.uv)

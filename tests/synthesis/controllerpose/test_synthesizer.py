"""ControllerPose's foot grounding (§4.3: a foot near the floor is anchored to it, a foot
above it is raised; unlike the paper's prototype, both feet may leave the floor), on known
poses: the standing rest pose of the synthesiser's own humanoid, feet moved by hand."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.body17_angles import angles_from_positions
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.synthesis.controllerpose.checkpoint import untrained
from avatarsim.synthesis.controllerpose.synthesizer import ControllerPose, KeypointRecording

LEFT = [INDEX["l_ankle"], INDEX["l_foot"]]
RIGHT = [INDEX["r_ankle"], INDEX["r_foot"]]


@pytest.fixture(scope="module")
def synth() -> ControllerPose:
    motion = generate("walk", duration_s=0.2, fps=30.0, seed=0)
    height = standing_height(motion)
    _, lengths = angles_from_positions(body17_positions(motion))
    no_frames = KeypointRecording(np.zeros(0), np.zeros((0, 4, 17, 2)), np.zeros((0, 4, 17)))
    return ControllerPose(untrained(lengths.mean(0) / height), no_frames, motion.skeleton, height)


def moved(pose: np.ndarray, joints: list[int], dx: float, dz: float) -> np.ndarray:
    out = pose.copy()
    out[joints, 0] += dx
    out[joints, 2] += dz
    return out


def test_a_planted_foot_stays_anchored_where_it_landed_on_the_floor(synth):
    synth.reset()
    standing = synth.rest_sites  # the humanoid standing: its feet on the floor
    # The network's foot jitters 2 cm above the floor and slides 3 cm; the other foot is
    # 30 cm up (a step).
    first = synth.grounded(moved(moved(standing, LEFT, 0.0, 0.02), RIGHT, 0.1, 0.3))
    later = synth.grounded(moved(moved(standing, LEFT, 0.03, 0.01), RIGHT, 0.2, 0.3))
    for out in (first, later):
        # On the floor (z = 0): the foot keypoint at the sole, the ankle a few cm above it.
        assert (out[LEFT, 2] >= 0.0).all() and out[LEFT, 2].max() < 0.1
        np.testing.assert_allclose(out[LEFT, 2], standing[LEFT, 2], atol=1e-9)
        np.testing.assert_allclose(out[LEFT, :2], standing[LEFT, :2], atol=1e-9)
    np.testing.assert_allclose(later[RIGHT], moved(standing, RIGHT, 0.2, 0.3)[RIGHT])
    # Everything but the anchored foot is the network's.
    others = np.setdiff1d(np.arange(17), LEFT)
    np.testing.assert_allclose(later[others], moved(standing, RIGHT, 0.2, 0.3)[others])


def test_both_feet_leave_the_floor_and_are_not_pulled_down(synth):
    synth.reset()
    standing = synth.rest_sites
    synth.grounded(standing)  # both planted first
    jump = moved(moved(standing, LEFT, 0.0, 0.25), RIGHT, 0.0, 0.25)
    np.testing.assert_allclose(synth.grounded(jump), jump)


def test_a_foot_that_lands_again_is_anchored_where_it_lands(synth):
    synth.reset()
    standing = synth.rest_sites
    synth.grounded(standing)
    synth.grounded(moved(standing, LEFT, 0.1, 0.3))  # lifted and carried forward
    landed = synth.grounded(moved(standing, LEFT, 0.4, 0.03))
    np.testing.assert_allclose(landed[LEFT, 0], standing[LEFT, 0] + 0.4, atol=1e-9)
    np.testing.assert_allclose(landed[LEFT, 2], standing[LEFT, 2], atol=1e-9)

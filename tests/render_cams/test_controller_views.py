"""The controller cameras see the user as in ControllerPose's Figs. 1, 4 and 5: with a hand
held in front of the chest, that controller's composite shows the whole body, unoccluded
(from the rendered range image), and a detector trained on photos of people finds it there."""

import numpy as np
import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.rig import camera_pairs
from avatarsim.render_cams.hand_location import hand_measures
from tests.conftest import require_module

SEEDS = (1, 2, 3)  # three study poses: split stance, lunge, heel back (one leg up)
IN_FRONT_M = 0.35  # wrist ahead of the body centre line (render_cams.hand_location)


@pytest.fixture(scope="module")
def recordings():
    """``{seed: (recording, controller)}``: the two frames of the study where a hand is
    furthest ahead (arm outstretched to its spheres), and that hand's controller."""
    out = {}
    for seed in SEEDS:
        motion = generate("controllerpose_study", duration_s=12.0, fps=30, seed=seed)
        in_front, distance = hand_measures(body17_positions(motion), IN_FRONT_M)  # (T, 2)
        t, hand = np.unravel_index(np.argmax(np.where(in_front, distance, -1.0)), distance.shape)
        assert in_front[t, hand]
        recording = FisheyeRig(bad_frame_rate=0.0).sample(motion[t : t + 2], seed)
        out[seed] = (recording, ("left_controller", "right_controller")[hand])
    return out


def test_composite_sees_the_body_past_the_holding_arm(recordings):
    for seed, (rec, controller) in recordings.items():
        comp = rec.views[controller].composite
        seen = (comp.in_image & comp.visible).sum(axis=1)  # (T,) of 17
        assert np.all(seen >= 12), (seed, controller, seen)


def test_blazepose_finds_the_person_in_a_composite(recordings):
    """MediaPipe BlazePose (standing in for the paper's OpenPose) on the composite images.
    On the primitive mannequin it is asked to find the person in at least one of these three
    views; a skinned body is what should make it find all three."""
    require_module("mediapipe.python.solutions.pose")
    from avatarsim.render_cams.fisheye.blazepose import BlazePoseDetector

    found = []
    with BlazePoseDetector() as detector:
        for rec, controller in recordings.values():
            pair = camera_pairs(rec.cameras)[controller]
            image = rec.views[controller].params.stitch([rec.images[c, 0] for c in pair])
            found.append(detector.detect(image).person)
    assert any(found), found

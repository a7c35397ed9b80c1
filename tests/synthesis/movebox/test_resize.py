"""Resizing the avatar to the user's height measured from the Kinect's head and feet."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect import kinect_skeleton
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.resize import resized, user_height_m


@pytest.mark.parametrize("height", [1.58, 1.9])
def test_height_from_head_and_feet(height):
    performer = generate("wave", Subject(height_m=height), duration_s=1.0, fps=30.0, seed=0)
    kinect = kinect_skeleton(performer, "kinect-v2", seed=0)
    avatar = load_rig("avatar").skeleton
    measured = user_height_m(kinect, avatar)
    # seeds 0-2: 1.581-1.591 m for 1.58 m, 1.897-1.907 m for 1.90 m
    assert measured == pytest.approx(height, abs=0.03)
    assert standing_height(resized(avatar, measured)) == pytest.approx(measured)


def test_no_full_view_no_height(noisy_kinect):
    from dataclasses import replace

    kinect = noisy_kinect["kinect-v2"]
    blind = replace(kinect, states=kinect.states * 0)
    with pytest.raises(SynthesisError, match="cannot measure"):
        user_height_m(blind, load_rig("avatar").skeleton)

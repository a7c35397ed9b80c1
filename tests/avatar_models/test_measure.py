"""Body measures: standing height on rigs of known height, lowest point, bone lengths."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.measure import (
    bone_lengths_over_time,
    lowest_point,
    path_length,
    standing_height,
)
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.avatar_models.skeleton import Skeleton


def test_body17_rig_height_within_five_percent():
    # body17.toml describes a 1.75 m adult.
    assert standing_height(load_rig("body17").skeleton) == pytest.approx(1.75, rel=0.05)


def test_height_scales_with_the_skeleton_and_ignores_pose():
    sk = load_rig("body17").skeleton
    assert standing_height(sk.scaled(1.2)) == pytest.approx(1.2 * standing_height(sk))
    rng = np.random.default_rng(0)
    rot = quat.normalize(rng.normal(size=(4, sk.n_joints, 4)))
    motion = Motion(sk, 30.0, rng.normal(size=(4, 3)), rot)
    assert standing_height(motion) == pytest.approx(standing_height(sk))


def test_unknown_rig_uses_upright_rest_extent():
    sk = Skeleton(["a", "b", "c"], [-1, 0, 1], [[0, 0, 0], [0.1, 0, 0.9], [0, 0, 0.8]])
    assert standing_height(sk) == pytest.approx(1.7)


def test_path_length_through_common_ancestor():
    sk = Skeleton(["r", "a", "b", "c"], [-1, 0, 1, 0], [[0, 0, 0], [0, 0, 1], [0, 2, 0], [3, 0, 0]])
    assert path_length(sk, 2, 3) == pytest.approx(6.0)
    assert path_length(sk, 1, 2) == pytest.approx(2.0)


def test_lowest_point_and_bone_lengths_on_a_known_pose():
    sk = Skeleton(["r", "a", "b"], [-1, 0, 1], [[0, 0, 0], [0, 0, -0.5], [0.3, 0, 0]])
    # Frame 1 turns the root 180 deg about X: the chain points up instead of down.
    rot = np.tile(quat.IDENTITY, (2, 3, 1))
    rot[1, 0] = [0.0, 1.0, 0.0, 0.0]
    motion = Motion(sk, 30.0, [[0, 0, 1.0], [0, 0, 1.0]], rot)
    np.testing.assert_allclose(lowest_point(motion), [0.5, 1.0])
    np.testing.assert_allclose(bone_lengths_over_time(motion), [[0, 0.5, 0.3]] * 2)

"""§4.3's features: unit directions and confidences per skeleton, masked missing skeletons,
VR features that do not change when the whole scene turns about the vertical."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.synthesis.controllerpose.features import (
    PER_SKELETON,
    FeatureError,
    Features,
    latest_sample,
    skeleton_features,
    vr_features,
)


def test_skeleton_features_are_unit_directions_and_confidences():
    rng = np.random.default_rng(0)
    uv = rng.uniform(0, 640, (5, 17, 2))
    conf = rng.uniform(0.5, 1.0, (5, 17))
    conf[0, 3] = 0.0  # joint 3 not detected in frame 0
    feats, found = skeleton_features(uv, conf)
    assert feats.shape == (5, PER_SKELETON) == (5, 289) and found.all()
    directions = feats[:, :272].reshape(5, 136, 2)
    norms = np.linalg.norm(directions, axis=-1)
    assert np.allclose(norms[1:], 1.0, atol=1e-6)
    assert (norms[0] == 0).sum() == 16  # the 16 pairs that touch joint 3
    # pair (0, 1) points from joint 0 to joint 1
    d01 = (uv[1, 1] - uv[1, 0]) / np.linalg.norm(uv[1, 1] - uv[1, 0])
    assert np.allclose(directions[1, 0], d01, atol=1e-6)
    assert np.allclose(feats[:, 272:], conf, atol=1e-6)


def test_a_view_with_few_joints_is_a_masked_skeleton():
    uv = np.random.default_rng(1).uniform(0, 640, (17, 2))
    conf = np.zeros(17)
    conf[:3] = 0.9
    feats, found = skeleton_features(uv, conf)
    assert not found and not feats.any()


def test_vr_features_do_not_change_when_the_scene_turns():
    rng = np.random.default_rng(2)
    head, hands = rng.normal(size=3) + [0, 0, 1.6], rng.normal(size=(2, 3))
    head_q, hands_q = quat.normalize(rng.normal(size=4)), quat.normalize(rng.normal(size=(2, 4)))
    turn = quat.from_axis_angle(np.array([0, 0, 1.0]), np.array(1.1))
    turned = vr_features(
        quat.rotate(turn, head),
        quat.mul(turn, head_q),
        quat.rotate(turn, hands),
        quat.mul(turn, hands_q),
    )
    plain = vr_features(head, head_q, hands, hands_q)
    assert plain.shape == (15,) and np.isclose(plain[0], head[2])
    assert np.allclose(turned, plain, atol=1e-5)


def test_latest_sample_never_reads_the_future():
    times = np.array([0.0, 0.1, 0.2, 0.3])
    valid = np.array([True, True, False, True])
    index, ok = latest_sample(times, valid, np.array([-0.05, 0.0, 0.25, 0.31]))
    assert list(ok) == [False, True, True, True]
    assert list(index[1:]) == [0, 1, 3]


def test_nan_features_raise_a_typed_error():
    features = Features(np.zeros((2, 4, 289)), np.ones((2, 4), bool), np.zeros((2, 15)))
    features.vr[1, 3] = np.nan
    with pytest.raises(FeatureError, match="frame 1"):
        features.check_finite("test")

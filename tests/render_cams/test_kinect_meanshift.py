"""Weighted mean shift (Shotton section 4) on point sets with known modes."""

from __future__ import annotations

import numpy as np

from avatarsim.render_cams.kinect.meanshift import densest_mode


def clusters(rng: np.random.Generator):
    """Two tight clusters, the light one first: 100 points at (0.5, 0, 2) and 300 at
    (0, 0, 2), 1 cm spread."""
    small = rng.normal([0.5, 0.0, 2.0], 0.01, (100, 3))
    big = rng.normal([0.0, 0.0, 2.0], 0.01, (300, 3))
    return np.concatenate([small, big]), np.ones(400)


def test_the_heavier_of_two_clusters_wins_and_its_weight_is_the_confidence():
    points, weights = clusters(np.random.default_rng(0))
    weights[:100] = 1.2  # the heaviest points are in the light cluster (120 against 300)
    # One more point 9 cm from the big cluster: outside the 6 cm that confidence counts.
    points = np.r_[points, [[0.0, 0.09, 2.0]]]
    mode, confidence = densest_mode(points, np.r_[weights, 1.0], 0.06)
    np.testing.assert_allclose(mode, points[100:400].mean(0), atol=2e-3)
    assert confidence == 300.0


def test_weights_decide_between_clusters():
    points, weights = clusters(np.random.default_rng(1))
    weights[:100] = 5.0  # the small cluster now weighs 500 against 300
    mode, confidence = densest_mode(points, weights, 0.06)
    np.testing.assert_allclose(mode, points[:100].mean(0), atol=2e-3)
    assert confidence == 500.0


def test_the_mode_of_two_close_points_is_their_weighted_mean():
    # 1 cm apart, far inside the 6 cm kernel: the fixed point is within 0.1 mm of the
    # weighted mean (x = 2.5 mm), half a centimetre from the unweighted one.
    points = np.array([[0.0, 0.0, 2.0], [0.01, 0.0, 2.0]])
    mode, confidence = densest_mode(points, np.array([3.0, 1.0]), 0.06)
    np.testing.assert_allclose(mode, [0.0025, 0.0, 2.0], atol=1e-4)
    assert confidence == 4.0


def test_a_single_point_is_its_own_mode():
    mode, confidence = densest_mode(np.array([[0.1, 0.2, 1.5]]), np.array([0.3]), 0.06)
    np.testing.assert_allclose(mode, [0.1, 0.2, 1.5])
    assert confidence == 0.3

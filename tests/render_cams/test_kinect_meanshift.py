"""Weighted mean shift (Shotton section 4) on point sets with known modes."""

from __future__ import annotations

import numpy as np

from render_cams.kinect.meanshift import densest_mode


def clusters(rng: np.random.Generator):
    """Two tight clusters: 300 points at (0, 0, 2) and 100 at (0.5, 0, 2), 1 cm spread."""
    a = rng.normal([0.0, 0.0, 2.0], 0.01, (300, 3))
    b = rng.normal([0.5, 0.0, 2.0], 0.01, (100, 3))
    return np.concatenate([a, b]), np.ones(400)


def test_the_heavier_of_two_clusters_wins_and_its_weight_is_the_confidence():
    points, weights = clusters(np.random.default_rng(0))
    mode, confidence = densest_mode(points, weights, 0.06)
    np.testing.assert_allclose(mode, points[:300].mean(0), atol=2e-3)
    assert confidence == 300.0


def test_weights_decide_between_clusters():
    points, weights = clusters(np.random.default_rng(1))
    weights[300:] = 5.0  # the small cluster now weighs 500 against 300
    mode, confidence = densest_mode(points, weights, 0.06)
    np.testing.assert_allclose(mode, points[300:].mean(0), atol=2e-3)
    assert confidence == 500.0


def test_a_single_point_is_its_own_mode():
    mode, confidence = densest_mode(np.array([[0.1, 0.2, 1.5]]), np.array([0.3]), 0.06)
    np.testing.assert_allclose(mode, [0.1, 0.2, 1.5])
    assert confidence == 0.3

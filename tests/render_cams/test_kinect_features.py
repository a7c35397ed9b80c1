"""Shotton's depth-difference features (eq. 1) on depth images with known geometry."""

from __future__ import annotations

import numpy as np

from avatarsim.render_cams.kinect.features import BACKGROUND_M, DepthFeatures, body_depth

K = np.array([[300.0, 0.0, 50.0], [0.0, 300.0, 40.0], [0.0, 0.0, 1.0]])


def step_depth(near_m: float, far_m: float, split_col: int) -> np.ndarray:
    """``(80, 100)`` depth: ``near_m`` left of ``split_col``, ``far_m`` from it on."""
    depth = np.full((80, 100), near_m, np.float32)
    depth[:, split_col:] = far_m
    return depth


def test_an_offset_in_metres_moves_f_times_u_over_d_pixels():
    # At 2 m, 0.1 m to the right is 300 * 0.1 / 2 = 15 px: from column 40 the probe lands on
    # column 55, past the step at 50, so the unary feature reads 3 m - 2 m.
    depth = step_depth(2.0, 3.0, 50)
    features = DepthFeatures(np.array([[0.1, 0.0], [0.05, 0.0]]), np.zeros((2, 2)))
    rows, cols = np.array([40]), np.array([40])
    values = features.evaluate(depth, K, rows, cols, np.array([[0, 1]]))
    # 0.05 m is 7.5 px, rounded to 8: column 48, still on the near side.
    np.testing.assert_allclose(values, [[1.0, 0.0]], atol=1e-6)


def test_the_same_body_point_reads_the_same_at_any_distance():
    # A step 0.1 m to the right of the pixel: 30 px away at 1 m, 15 px at 2 m. A probe
    # 0.12 m across crosses it at both distances, one 0.08 m across at neither (a fixed
    # 24 px offset would cross it at 2 m only).
    features = DepthFeatures(np.array([[0.12, 0.0], [0.08, 0.0]]), np.zeros((2, 2)))
    for d, split in ((1.0, 40 + 30), (2.0, 40 + 15)):
        depth = step_depth(d, d + 0.5, split)
        value = features.evaluate(depth, K, np.array([40]), np.array([40]), np.array([[0, 1]]))
        np.testing.assert_allclose(value, [[0.5, 0.0]], atol=1e-6)


def test_probes_outside_the_image_read_the_background():
    depth = np.full((80, 100), 2.0, np.float32)
    features = DepthFeatures(np.array([[0.0, -1.0]]), np.array([[0.0, 0.0]]))  # far above
    value = features.evaluate(depth, K, np.array([10]), np.array([50]), np.array([0]))
    np.testing.assert_allclose(value, [BACKGROUND_M - 2.0])


def test_binary_features_take_the_difference_of_both_probes():
    # Left of column 50 at 2 m, right at 3 m; from column 50 at 2.5 m (its own depth is
    # the far side) u reaches 12 px left, v 12 px right: 2 - 3.
    depth = step_depth(2.0, 3.0, 50)
    depth[:, 50] = 2.5
    features = DepthFeatures(np.array([[-0.1, 0.0]]), np.array([[0.1, 0.0]]))
    value = features.evaluate(depth, K, np.array([30]), np.array([50]), np.array([0]))
    np.testing.assert_allclose(value, [-1.0], atol=1e-6)


def test_sampled_offsets_lie_in_the_disc_and_half_are_unary():
    features = DepthFeatures.sample(200, 0.5, np.random.default_rng(3))
    assert len(features) == 200
    assert np.all(np.linalg.norm(features.u, axis=1) <= 0.5)
    assert np.all(features.v[100:] == 0.0)
    assert np.all(np.linalg.norm(features.v[:100], axis=1) > 0.0)


def test_body_depth_keeps_the_body_and_drops_missing_readings():
    depth_mm = np.array([[1500.0, 0.0], [np.nan, 2500.0]])
    body_index = np.array([[0, 0], [0, 255]], np.uint8)
    out = body_depth(depth_mm, body_index)
    np.testing.assert_allclose(out, [[1.5, BACKGROUND_M], [BACKGROUND_M, BACKGROUND_M]])

"""The SDK's Holt double exponential smoothing against its equations on known signals."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.render_cams.kinect.sensors import KinectError
from avatarsim.render_cams.kinect.smoothing import SmoothParameters, smooth_joints


def one_joint(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``x (T,)`` metres along X as one joint's raw track, all live, none inferred."""
    raw = np.zeros((len(x), 1, 3))
    raw[:, 0, 0] = x
    return raw, np.ones((len(x), 1), bool), np.zeros((len(x), 1), bool)


def holt_reference(x: np.ndarray, a: float, c: float, p: float) -> np.ndarray:
    """Holt's level/trend recursion as the SDK white paper writes it, scalar, no jitter
    filter and no deviation clamp: level_1 = x_1, level_2 = (x_1 + x_2) / 2, then
    level_t = (1 - a) x_t + a (level_{t-1} + trend_{t-1}); trend_t = c (level_t -
    level_{t-1}) + (1 - c) trend_{t-1}; output level_t + p trend_t."""
    out, level, trend = [], 0.0, 0.0
    for t, xt in enumerate(x):
        if t == 0:
            new_level, new_trend = xt, 0.0
        else:
            new_level = 0.5 * (xt + x[t - 1]) if t == 1 else (1 - a) * xt + a * (level + trend)
            new_trend = c * (new_level - level) + (1 - c) * trend
        level, trend = new_level, new_trend
        out.append(level + p * trend)
    return np.array(out)


def test_without_jitter_filter_or_clamp_it_is_holts_recursion():
    x = np.random.default_rng(0).normal(0.0, 0.02, 40).cumsum()
    params = SmoothParameters(0.6, 0.3, 0.7, jitter_radius_m=0.0, max_deviation_radius_m=10.0)
    out = smooth_joints(*one_joint(x), params)
    np.testing.assert_allclose(out[:, 0, 0], holt_reference(x, 0.6, 0.3, 0.7), atol=1e-12)
    np.testing.assert_allclose(out[:, 0, 1:], 0.0)


def test_a_ramp_is_followed_with_the_predicted_lead():
    # Level -> x_t and trend -> the slope v, so the output leads the ramp by p * v.
    v = 0.01
    x = v * np.arange(120)
    params = SmoothParameters(0.5, 0.5, 0.5, jitter_radius_m=0.0, max_deviation_radius_m=1.0)
    out = smooth_joints(*one_joint(x), params)[:, 0, 0]
    np.testing.assert_allclose(out[-10:], x[-10:] + 0.5 * v, atol=1e-9)


def test_the_output_stays_within_the_max_deviation_of_the_raw_input():
    x = np.r_[np.zeros(20), np.ones(20)]  # a 1 m jump
    params = SmoothParameters(0.9, 0.5, 0.5, jitter_radius_m=0.0, max_deviation_radius_m=0.04)
    out = smooth_joints(*one_joint(x), params)[:, 0, 0]
    assert np.max(np.abs(out - x)) <= 0.04 + 1e-12
    assert abs(out[20] - x[20]) == pytest.approx(0.04)  # the jump is clamped, not followed


def test_jitter_inside_the_radius_is_damped():
    x = 1.0 + 0.005 * (-1.0) ** np.arange(60)  # 5 mm flicker about 1 m
    params = SmoothParameters(0.0, 0.0, 0.0, jitter_radius_m=0.05, max_deviation_radius_m=1.0)
    out = smooth_joints(*one_joint(x), params)[:, 0, 0]
    # With no smoothing the output is the jitter-filtered input: each step is pulled to the
    # last level by |diff| / radius, so the flicker shrinks far below its 1 cm peak to peak.
    assert np.ptp(out[30:]) < 0.2 * np.ptp(x[30:])


def test_a_lost_joint_comes_out_nan_and_restarts_at_the_raw_input():
    x = 0.01 * np.arange(30)
    raw, live, inferred = one_joint(x)
    live[10:15] = False
    out = smooth_joints(raw, live, inferred, SmoothParameters())
    assert np.all(np.isnan(out[10:15]))
    np.testing.assert_allclose(out[15, 0], raw[15, 0])


def test_parameters_outside_their_ranges_are_refused():
    with pytest.raises(KinectError, match="smoothing and correction"):
        SmoothParameters(smoothing=1.5)
    with pytest.raises(KinectError, match="non-negative"):
        SmoothParameters(jitter_radius_m=-0.1)

"""The Kinect SDK's joint smoothing: Holt double exponential smoothing with jitter removal.

Kinect for Windows SDK 1.x ``TransformSmoothParameters`` and its V2 sample filter
(``KinectJointFilter``, Microsoft, "Skeletal Joint Smoothing White Paper", 2012): per joint,
a level and a trend (Holt), raw input within ``jitter_radius`` of the last output pulled
towards it, and the prediction never more than ``max_deviation_radius`` from the raw input.
A joint that is not tracked resets its filter; an Inferred joint is smoothed more (jitter and
deviation radii doubled), as the sample filter does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.kinect.sensors import KinectError


@dataclass(frozen=True)
class SmoothParameters:
    """``TransformSmoothParameters`` (SDK defaults: 0.5, 0.5, 0.5, 0.05 m, 0.04 m).

    Attributes:
        smoothing: 0 (raw) .. 1 (frozen): weight of the Holt prediction.
        correction: 0 .. 1: how fast the trend follows the data.
        prediction: frames of trend extrapolated into the output.
        jitter_radius_m: input changes smaller than this are damped.
        max_deviation_radius_m: the output stays this close to the raw input.
    """

    smoothing: float = 0.5
    correction: float = 0.5
    prediction: float = 0.5
    jitter_radius_m: float = 0.05
    max_deviation_radius_m: float = 0.04

    def __post_init__(self) -> None:
        values = (self.smoothing, self.correction)
        if not all(0.0 <= v <= 1.0 for v in values):
            raise KinectError(f"smoothing and correction must be in [0, 1], got {values}")
        others = (self.prediction, self.jitter_radius_m, self.max_deviation_radius_m)
        if not all(np.isfinite(v) and v >= 0 for v in others):
            raise KinectError(f"prediction and radii must be non-negative, got {others}")


def smooth_joints(
    raw: np.ndarray, live: np.ndarray, inferred: np.ndarray, params: SmoothParameters
) -> np.ndarray:
    """``(T, J, 3)`` smoothed positions of ``raw (T, J, 3)``; ``live (T, J)`` bool marks the
    samples the filter sees (others reset it and come out NaN), ``inferred (T, J)`` bool the
    Inferred ones."""
    n_frames, n_joints, _ = raw.shape
    out = np.full(raw.shape, np.nan)
    level = np.zeros((n_joints, 3))
    trend = np.zeros((n_joints, 3))
    previous = np.zeros((n_joints, 3))
    seen = np.zeros(n_joints, int)  # frames since the last reset
    for t in range(n_frames):
        x = raw[t]
        on = live[t]
        seen = np.where(on, seen + 1, 0)
        wider = np.where(inferred[t], 2.0, 1.0)[:, None]
        jitter = wider * params.jitter_radius_m
        deviation = wider * params.max_deviation_radius_m
        correction = params.correction
        first, second = seen == 1, seen == 2
        # Third sample on: jitter removal, then Holt's level and trend.
        diff = x - level
        length = np.linalg.norm(diff, axis=1, keepdims=True)
        pull = np.minimum(length / np.maximum(jitter, 1e-12), 1.0)
        damped = x * pull + level * (1.0 - pull)
        new_level = damped * (1 - params.smoothing) + (level + trend) * params.smoothing
        new_level = np.where(second[:, None], 0.5 * (x + previous), new_level)
        new_level = np.where(first[:, None], x, new_level)
        new_trend = (new_level - level) * correction + trend * (1.0 - correction)
        new_trend = np.where(first[:, None], 0.0, new_trend)
        predicted = new_level + new_trend * params.prediction
        gap = predicted - x
        gap_len = np.linalg.norm(gap, axis=1, keepdims=True)
        far = gap_len > deviation
        predicted = np.where(far, x + gap * deviation / np.maximum(gap_len, 1e-12), predicted)
        level = np.where(on[:, None], new_level, 0.0)
        trend = np.where(on[:, None], new_trend, 0.0)
        previous = x
        out[t] = np.where(on[:, None], predicted, np.nan)
    return out

"""Rolling windows of head-relative hand positions and their matching features.

CoolMoves §3.1.2: every trial is resampled to 90 Hz, made head-relative (the head position is
subtracted, head rotation is *not* normalised), and cut into rolling windows of 100 ms
(9 samples) overlapping by 50 ms. A hand's feature vector is its 3D positions over the
window concatenated with their velocity and acceleration; the database is augmented with
windows up to 50 % faster and slower, the change "back-propagated" to the positions.

Units (the paper does not give them): velocity is multiplied by the window duration ``W`` and
acceleration by ``W**2``, so that all three parts are lengths (metres moved over one window)
and no part dominates the L2 distance by its unit alone.

Exact dimension reduction: velocity and acceleration are linear in the positions,
``f = M p`` per axis with ``M = [I; W D; W^2 D^2]`` (``D`` the finite-difference operator), so
``|f_a - f_b| = |L^T (p_a - p_b)|`` with ``L L^T = M^T M`` (Cholesky). Searching the
``9 x 3 = 27``-dimensional ``L^T p`` instead of the 81-dimensional ``f`` gives the same
neighbours at the same L2 distances, three times cheaper.
"""

from __future__ import annotations

from functools import cache

import numpy as np

RATE_HZ = 90.0
"""Tracking rate of the HTC Vive, to which every trial is resampled (§3.1.2)."""
WINDOW_SAMPLES = 9
"""100 ms rolling window, "9 samples of data" at 90 Hz (§3.1.2)."""
OVERLAP_S = 0.05
"""Overlap of neighbouring windows (§3.1.2)."""
SPEED_FACTORS = (0.5, 0.75, 1.0, 1.25, 1.5)
"""Speed augmentation "up to 50 % increase and decrease" of velocity and acceleration (§3.1.2);
the intermediate steps are our choice."""


def window_stride(n: int = WINDOW_SAMPLES, rate_hz: float = RATE_HZ) -> int:
    """Samples between window starts: the window minus the 50 ms overlap (ceil: 5 -> stride 4)."""
    return n - int(np.ceil(OVERLAP_S * rate_hz - 1e-9))


@cache
def _operator(n: int, rate_hz: float) -> np.ndarray:
    """``(3n, n)`` matrix mapping a window of positions to [position; W vel; W^2 acc]."""
    dt = 1.0 / rate_hz
    width = (n - 1) * dt
    d1 = np.gradient(np.eye(n), dt, axis=0)  # central differences, one-sided at the ends
    return np.concatenate([np.eye(n), width * d1, width**2 * (d1 @ d1)])


def feature_vectors(windows: np.ndarray, rate_hz: float = RATE_HZ) -> np.ndarray:
    """Full paper features ``(..., 3n * 3)`` of position windows ``(..., n, 3)``:
    positions, velocities and accelerations (each ``n x 3``), flattened."""
    windows = np.asarray(windows, dtype=float)
    m = _operator(windows.shape[-2], float(rate_hz))
    return np.einsum("fi,...ic->...fc", m, windows).reshape(*windows.shape[:-2], -1)


@cache
def _reduction(n: int, rate_hz: float) -> np.ndarray:
    """``(n, n)`` upper-triangular ``L^T`` with ``L L^T = M^T M`` (see the module docstring)."""
    m = _operator(n, rate_hz)
    return np.ascontiguousarray(np.linalg.cholesky(m.T @ m).T)


def search_vectors(windows: np.ndarray, rate_hz: float = RATE_HZ) -> np.ndarray:
    """``(..., n * 3)`` vectors whose L2 distances equal those of :func:`feature_vectors`."""
    windows = np.asarray(windows, dtype=float)
    lt = _reduction(windows.shape[-2], float(rate_hz))
    return np.einsum("fi,...ic->...fc", lt, windows).reshape(*windows.shape[:-2], -1)


def sliding_windows(series: np.ndarray, ends: np.ndarray, n: int = WINDOW_SAMPLES) -> np.ndarray:
    """``(E, n, ...)`` windows of ``series (T, ...)`` ending (inclusive) at frames ``ends (E,)``."""
    idx = np.asarray(ends)[:, None] + np.arange(-(n - 1), 1)[None, :]
    return series[idx]


def speed_windows(
    series: np.ndarray,
    ends: np.ndarray,
    speed: float,
    n: int = WINDOW_SAMPLES,
) -> np.ndarray:
    """``(E, n, ...)`` windows of ``series (T, ...)`` played ``speed`` times as fast.

    The window keeps its last sample (the pose it stands for) and reaches back
    ``speed * (n - 1)`` frames, linearly interpolated: velocity scales by ``speed`` and
    acceleration by ``speed**2``, the §3.1.2 augmentation expressed on the positions.
    ``ends - speed * (n - 1)`` must be >= 0.
    """
    t = np.asarray(ends, float)[:, None] - speed * np.arange(n - 1, -1, -1.0)[None, :]
    lo = np.floor(t).astype(np.int64)
    hi = np.minimum(lo + 1, series.shape[0] - 1)
    frac = (t - lo).reshape(t.shape + (1,) * (series.ndim - 1))
    return (1.0 - frac) * series[lo] + frac * series[hi]

"""Weighted mean shift with a Gaussian kernel: the densest mode of a 3D point set.

Shotton et al. (CVPR 2011, section 4, eq. 6) find joint proposals as the modes of the density
``f(x) = sum_i w_i exp(-||(x - x_i) / b||^2)`` of a part's pixels reprojected into the world,
by mean shift (Comaniciu and Meer 2002). Seeds are the weighted centres of the heaviest cells
of a grid one bandwidth wide (scikit-learn's ``bin_seeding``), so every cluster of weight gets
a seed whatever the order of the points; every seed climbs to its mode, the mode with the
highest density wins, and the weight within one bandwidth of it is its confidence. A body
part spans a few cells, so :data:`SEEDS` of the heaviest cells already hold its densest mode.
"""

from __future__ import annotations

import numpy as np

SEEDS = 8
"""Seeds per part: the heaviest cells; more seeds cost time and find the same modes."""
ITERATIONS = 12
"""Mean-shift steps per seed (the modes move by under 1 mm after ~8 on body parts)."""


def densest_mode(
    points: np.ndarray, weights: np.ndarray, bandwidth_m: float, n_seeds: int = SEEDS
) -> tuple[np.ndarray, float]:
    """The densest mode ``(3,)`` of ``points (N, 3)`` weighted by ``weights (N,)`` (N >= 1)
    and the total weight of the points within ``bandwidth_m`` of it; seeds from the
    ``n_seeds`` heaviest grid cells."""
    modes = _cell_seeds(points, weights, bandwidth_m, n_seeds)
    scale = -1.0 / bandwidth_m**2
    for _ in range(ITERATIONS):
        kernel = np.exp(scale * _squared_distances(modes, points)) * weights  # (S, N)
        modes = kernel @ points / np.maximum(kernel.sum(1, keepdims=True), 1e-300)
    density = (np.exp(scale * _squared_distances(modes, points)) * weights).sum(1)
    best = modes[int(np.argmax(density))]
    near = np.sum((points - best) ** 2, axis=1) <= bandwidth_m**2
    return best, float(weights[near].sum())


def _cell_seeds(points, weights, size_m: float, n_seeds: int) -> np.ndarray:
    """``(S, 3)`` weighted centres of the ``S <= n_seeds`` heaviest cells of side ``size_m``."""
    _, cell = np.unique(np.floor(points / size_m).astype(np.int64), axis=0, return_inverse=True)
    cell = cell.ravel()
    total = np.bincount(cell, weights)
    centres = np.stack([np.bincount(cell, weights * p) for p in points.T], 1)
    heaviest = np.argsort(-total, kind="stable")[:n_seeds]
    return centres[heaviest] / np.maximum(total[heaviest, None], 1e-300)


def _squared_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(A, B)`` squared distances between ``a (A, 3)`` and ``b (B, 3)``."""
    return np.maximum(np.sum(a * a, 1)[:, None] + np.sum(b * b, 1)[None] - 2.0 * a @ b.T, 0.0)

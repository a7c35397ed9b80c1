"""The hand-foot Pearson correlation filter of the motion database (CoolMoves §3.1.2).

"We achieve this by correlating the motions of the hands with the feet and only keep the ones
that have a high correlation ... treating the hands and the feet as a 3-dimensional time
series (X, Y, Z position) across the entire motion sequence ... we choose a relatively high
threshold of 0.1."

Our reading: for every hand-foot pair (left/right hand x left/right foot) and every axis, the
Pearson coefficient between the two head-relative coordinate series; a trial's score is the
mean of their absolute values. Absolute, because gait couples each arm with the *opposite*
leg (anti-phase, r < 0 for the same side): a signed mean would cancel exactly the coupling
the filter looks for. A series that does not vary has no defined coefficient and counts 0.
"""

from __future__ import annotations

import numpy as np

CORRELATION_THRESHOLD = 0.1
"""Trials whose hand-foot correlation is below this are discarded (§3.1.2)."""


def pearson(a: np.ndarray, b: np.ndarray, axis: int = 0) -> np.ndarray:
    """Pearson coefficient of ``a`` and ``b`` along ``axis``; 0 where either is constant."""
    a = np.asarray(a, float) - np.mean(a, axis=axis, keepdims=True)
    b = np.asarray(b, float) - np.mean(b, axis=axis, keepdims=True)
    num = np.sum(a * b, axis=axis)
    den = np.sqrt(np.sum(a * a, axis=axis) * np.sum(b * b, axis=axis))
    scale = np.maximum(np.abs(a).max(axis=axis), np.abs(b).max(axis=axis))
    # Constant series (up to rounding noise relative to the values) have no coefficient.
    defined = den > 1e-12 * np.maximum(scale, 1e-300) ** 2 * a.shape[axis]
    return np.where(defined, num / np.where(defined, den, 1.0), 0.0)


def hand_foot_correlation(hands: np.ndarray, feet: np.ndarray) -> float:
    """Mean absolute Pearson coefficient of ``hands (T, 2, 3)`` with ``feet (T, 2, 3)`` over
    all four hand-foot pairs and the three axes (head-relative positions)."""
    r = pearson(hands[:, :, None, :], feet[:, None, :, :], axis=0)  # (2 hands, 2 feet, 3)
    return float(np.mean(np.abs(r)))


def keeps(hands: np.ndarray, feet: np.ndarray, threshold: float = CORRELATION_THRESHOLD) -> bool:
    """Whether a trial passes the filter (correlation at least ``threshold``)."""
    return hand_foot_correlation(hands, feet) >= threshold

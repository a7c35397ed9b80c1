"""Weighted closed-form rotation alignment about the up axis (CoolMoves §3.1.4).

Before blending, each matched database pose is turned about the vertical axis so that its
hand window best fits the query's, treating the hand positions as a temporal point cloud. The
paper's variant of Kovar & Gleicher's closed form (Y up in the paper, ``x, z`` horizontal)::

    num   = sum c (x_q z_s - x_s z_q) - (sum c x_q  sum c z_s - sum c x_s  sum c z_q) / sum c
    den   = sum c (x_q x_s + z_s z_q) - (sum c x_q  sum c x_s + sum c z_s  sum c z_q) / sum c
    theta = arctan(num / den)

``q`` the input window, ``s`` the database window, sums over the ``n`` samples of both
hands, and ``c_i`` the contribution of each sample, "from 0 to 1, increasing in step-size
1/n from the start of the feature vector (0 ms) to the end (100 ms)": ``c_i = (i + 1) / n``,
so the newest sample counts fully. The ``1 / sum c`` terms make the angle independent of a
horizontal translation between the clouds.

Here Z is up: the paper's ``(x, z)`` are our ``(y, x)`` (the Y-up to Z-up map of the BVH
reader), which gives the same formula with ``x, y`` exchanged. ``atan2`` keeps the quadrant:
rotating the database cloud by ``+theta`` about +Z minimises the weighted squared distance to
the query cloud.
"""

from __future__ import annotations

import numpy as np


def ramp_weights(n: int) -> np.ndarray:
    """``(n,)`` contributions ``c_i = (i + 1) / n``, oldest sample first (§3.1.4)."""
    return np.arange(1, n + 1) / n


def alignment_yaw(
    query: np.ndarray, source: np.ndarray, side_weights: np.ndarray | None = None
) -> np.ndarray:
    """Yaw ``theta`` (radians) turning each ``source`` window onto its ``query``.

    Args:
        query: ``(B, n, S, 3)`` head-relative positions of ``S`` points (hands) over ``n``
            samples; non-finite values are allowed where ``side_weights`` is 0.
        source: ``(B, K, n, S, 3)`` the ``K`` matched database windows per query.
        side_weights: ``(B, S)`` extra weight per point (0 drops an untracked hand).
    Returns:
        ``(B, K)`` angles in ``(-pi, pi]``.
    """
    n, sides = query.shape[1], query.shape[2]
    c = np.broadcast_to(ramp_weights(n)[:, None], (n, sides))[None]  # (1, n, S)
    if side_weights is not None:
        c = c * np.asarray(side_weights, float)[:, None, :]
    query = np.where(c[..., None] > 0, query, 0.0)
    # Our (x, y) are the paper's (z, x): name them as in the paper to keep its formula.
    xq, zq = query[..., 1], query[..., 0]  # (B, n, S)
    xs, zs = source[..., 1], source[..., 0]  # (B, K, n, S)
    cq = c[:, None]  # (B|1, 1, n, S)
    total = np.maximum(c.sum(axis=(1, 2)), 1e-12)[:, None]  # (B|1, 1)

    def wsum(a: np.ndarray) -> np.ndarray:
        return (cq * a).sum(axis=(-2, -1))

    xq_, zq_ = xq[:, None], zq[:, None]
    num = wsum(xq_ * zs - xs * zq_) - (wsum(xq_) * wsum(zs) - wsum(xs) * wsum(zq_)) / total
    den = wsum(xq_ * xs + zs * zq_) - (wsum(xq_) * wsum(xs) + wsum(zs) * wsum(zq_)) / total
    return np.arctan2(num, den)

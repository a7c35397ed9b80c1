"""Weighted closed-form rotation alignment about the up axis (CoolMoves §3.1.4).

Before blending, each matched database pose is turned about the vertical axis so that its
hand window best fits the query's, treating the hand positions as a temporal point cloud. The
paper's variant of Kovar & Gleicher's closed form (Y up in the paper, ``x, z`` horizontal)::

    num   = sum c (x_q z_s - x_s z_q) - (sum c x_q  sum c z_s - sum c x_s  sum c z_q) / sum c
    den   = sum c (x_q x_s + z_s z_q) - (sum c x_q  sum c x_s + sum c z_s  sum c z_q) / sum c
    theta = arctan(num / den)

``q`` the input window, ``s`` the database window, sums over the ``n`` samples of both
hands, and ``c_i`` the contribution of each sample: "We assign the c_i from 0 to 1,
increasing them in step-size 1/n from the start of the feature vector (0 ms) to the end
(100 ms)": ``c_i = i / n``, ``i = 0 .. n-1``, so the oldest sample counts 0. With ``n``
samples the printed range and step cannot both hold (the last is ``(n - 1) / n``); the other
reading, ``i / (n - 1)``, differs by a constant factor, which both the numerator and the
denominator carry (the centroid terms too: ``c c / sum c`` scales like ``c``), so the angle is
the same either way.

Pivot. The ``1 / sum c`` terms come from Kovar & Gleicher, who solve for a rotation *and* a
horizontal translation: they make the angle that of the clouds about their weighted centroids
(``free_translation=True``, the paper's printed equation). CoolMoves has no such translation
to spend: the windows are head-relative and the turned pose is then placed so that its
headset is the tracked one, i.e. it is turned about the head. The least-squares yaw about the
head is the same formula without the centroid terms (``free_translation=False``, our
default). Why it matters: in a 100 ms window each hand barely moves, so the centred cloud is
little more than the left-to-right hand vector, whose direction changes with every punch or
arm swing; fitting it turned matches by a median 14 deg (p90 87 deg) on built-in subjects who
all face +X, and raised the full-body error by 3.2 cm. About the head, the forward reach of
both hands anchors the angle (+0.8 cm there; on the same subjects turned to random headings
the head pivot is also the better one, 22.0 vs 23.2 cm; ``synthesis.evaluate``).

Here Z is up: the paper's ``(x, z)`` are our ``(y, x)`` (the Y-up to Z-up map of the BVH
reader), which gives the same formula with ``x, y`` exchanged. ``atan2`` keeps the quadrant:
rotating the database cloud by ``+theta`` about +Z minimises the weighted squared distance to
the query cloud.
"""

from __future__ import annotations

from functools import cache

import numpy as np

_SWAP_SIGNS = np.array([-1.0, -1.0, 1.0, 1.0])  # (z, y, x, w) -> (-z, -y, x, w)


@cache
def ramp_weights(n: int) -> np.ndarray:
    """``(n,)`` contributions ``c_i = i / n``, from 0 in steps of ``1 / n``, oldest sample
    first (§3.1.4); read-only (one array per ``n``, shared by every step)."""
    ramp = np.arange(n) / n
    ramp.flags.writeable = False
    return ramp


def alignment_yaw(
    query: np.ndarray,
    source: np.ndarray,
    side_weights: np.ndarray | None = None,
    free_translation: bool = False,
) -> np.ndarray:
    """Yaw ``theta`` (radians) turning each ``source`` window onto its ``query``.

    Args:
        query: ``(B, n, S, 3)`` head-relative positions of ``S`` points (hands) over ``n``
            samples; non-finite values are allowed where ``side_weights`` is 0.
        source: ``(B, K, n, S, 3)`` the ``K`` matched database windows per query.
        side_weights: ``(B, S)`` extra weight per point (0 drops an untracked hand), or
            ``(B, K, S)`` per match (e.g. one hand's matches fitted on that hand only).
        free_translation: True for the paper's printed equation (the clouds turned about
            their weighted centroids); False turns them about the head (the origin).
    Returns:
        ``(B, K)`` angles in ``(-pi, pi]``.
    """
    n, sides = query.shape[1], query.shape[2]
    if side_weights is None:
        cq = np.broadcast_to(ramp_weights(n)[:, None], (n, sides))[None, None]  # (1, 1, n, S)
    else:
        w = np.asarray(side_weights, float)
        w = w[:, None] if w.ndim == 2 else w  # (B, 1|K, S)
        cq = ramp_weights(n)[:, None] * w[:, :, None, :]  # (B, 1|K, n, S)
    used = cq[:, 0] > 0 if cq.shape[1] == 1 else np.any(cq > 0, axis=1)  # (B|1, n, S)
    query = np.where(used[..., None], query, 0.0)
    # Our (x, y) are the paper's (z, x): name them as in the paper to keep its formula.
    xq, zq = query[..., 1], query[..., 0]  # (B, n, S)
    xs, zs = source[..., 1], source[..., 0]  # (B, K, n, S)

    def wsum(a: np.ndarray) -> np.ndarray:
        return np.add.reduce(cq * a, axis=(-2, -1))

    xq_, zq_ = xq[:, None], zq[:, None]
    num = wsum(xq_ * zs - xs * zq_)
    den = wsum(xq_ * xs + zs * zq_)
    if free_translation:
        total = np.maximum(cq.sum(axis=(-2, -1)), 1e-12)  # (B|1, 1|K)
        num = num - (wsum(xq_) * wsum(zs) - wsum(xs) * wsum(zq_)) / total
        den = den - (wsum(xq_) * wsum(xs) + wsum(zs) * wsum(zq_)) / total
    return np.arctan2(num, den)


def turn_about_vertical(rotations: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """``rotations (..., 4)`` wxyz turned by ``yaw (...)`` radians about +Z (applied after
    them): ``quat.mul(quat.from_axis_angle(Z, yaw), rotations)`` with its zero terms left
    out, the same numbers in a few numpy calls (it runs on every match of every step):
    ``(c w - s z, c x - s y, c y + s x, c z + s w)`` for ``c, s`` the cosine and sine of
    half the angle, i.e. ``c q + s (-z, -y, x, w)``."""
    half = 0.5 * np.asarray(yaw, float)[..., None]
    return np.cos(half) * rotations + np.sin(half) * (rotations[..., ::-1] * _SWAP_SIGNS)

"""Balance: the centre of mass projected on the floor against the support polygon (cm).

The support polygon is the convex hull of the sole corners in contact (a foot's corners
count when any of its sole points is in contact). The per-frame value is how far the CoM
lies outside it: the largest outside distance to a hull edge's line, as scipy's
``ConvexHull.equations`` would give (> 0 outside, 0 inside, NaN without support). The hull
edges are found for all frames at once (a pair of points is an edge when every other point
lies on its left), since a scipy hull per frame costs 65 us, more than all other kinematic
checks together. Informative: walking and running are dynamically balanced, so no threshold.
"""

from __future__ import annotations

import numpy as np

from sim.checks.base import CheckResult
from sim.checks.replay import BodyReplay
from sim.thresholds import CheckConfig

CHUNK = 512  # frames per vectorised batch: (CHUNK, K, K, K) floats stay a few MB


def outside_margin(points: np.ndarray, active: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``(T,)`` distance of ``p (T, 2)`` outside the convex hull of the ``active (T, K)`` of
    ``points (T, K, 2)`` (at least 3 non-collinear active points per frame; NaN with none)."""
    out = np.full(len(p), np.nan)
    for a in range(0, len(p), CHUNK):
        P, m, q = points[a : a + CHUNK], active[a : a + CHUNK], p[a : a + CHUNK]
        d = P[:, None, :, :] - P[:, :, None, :]  # (t, i, j, 2) edge i -> j
        rel = P[:, None, :, :] - P[:, :, None, :]  # (t, i, k, 2) point k from i
        cross = (
            d[:, :, :, None, 0] * rel[:, :, None, :, 1]
            - d[:, :, :, None, 1] * rel[:, :, None, :, 0]
        )  # (t, i, j, k): > 0 when k is left of i -> j
        length = np.linalg.norm(d, axis=-1)
        left = (cross >= -1e-9 * length[..., None]) | ~m[:, None, None, :]
        edge = left.all(axis=-1) & m[:, :, None] & m[:, None, :] & (length > 1e-9)
        to_p = q[:, None, :] - P  # (t, i, 2)
        side = d[..., 0] * to_p[:, :, None, 1] - d[..., 1] * to_p[:, :, None, 0]
        dist = np.where(edge, -side / np.where(length > 0, length, 1.0), -np.inf)
        best = dist.reshape(len(q), -1).max(axis=1)
        out[a : a + CHUNK] = np.where(np.isfinite(best), np.maximum(best, 0.0), np.nan)
    return out


class Balance:
    name = "balance"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        corners = replay.sole_corners[..., :2]  # (T, 2, C, 2)
        feet = replay.foot_contact  # (T, 2)
        n, _, c, _ = corners.shape
        active = np.repeat(feet, c, axis=1)  # (T, 2C)
        margin_cm = 100.0 * outside_margin(corners.reshape(n, 2 * c, 2), active, replay.com[:, :2])
        supported = np.isfinite(margin_cm)
        outside = supported & (margin_cm > 0)
        return CheckResult(
            name=self.name,
            per_frame={"com_outside_support_cm": margin_cm},
            values={"com_outside_support_frac": float(outside.sum() / max(supported.sum(), 1))},
            flagged=np.zeros(replay.n_frames, dtype=bool),
        )

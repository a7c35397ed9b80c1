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

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig

CHUNK = 512  # frames per vectorised batch: (CHUNK, K, K, K) floats stay a few MB


def outside_margin(points: np.ndarray, active: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``(T,)`` distance of ``p (T, 2)`` outside the convex hull of the ``active (T, K)`` of
    ``points (T, K, 2)`` (at least 3 non-collinear active points per frame; NaN with none).

    With the points ``Q`` taken relative to ``p`` and ``C[i, j] = Q_i x Q_j`` (2D cross), the
    turn of ``k`` about the edge ``i -> j`` is ``C[i, j] + C[j, k] - C[i, k]`` and the side of
    ``p`` is ``C[i, j]``, so the edge test over all ``k`` is one subtraction and a minimum over a
    ``(K, K, K)`` block. Inactive points are moved onto an active one of their frame: a
    duplicate changes no turn and adds only copies of real edges, so no masks are needed.
    """
    out = np.full(len(p), np.nan)
    some = active.any(axis=1)
    first = np.argmax(active, axis=1)  # an active point of each supported frame
    stand_in = np.take_along_axis(points, first[:, None, None], axis=1)  # (T, 1, 2)
    q = np.where(active[..., None], points, stand_in) - p[:, None, :]  # (T, K, 2)
    for a in range(0, len(p), CHUNK):
        x, y = q[a : a + CHUNK, :, 0], q[a : a + CHUNK, :, 1]
        cross = x[:, :, None] * y[:, None, :] - y[:, :, None] * x[:, None, :]  # (t, i, j)
        worst_turn = np.full(cross.shape, np.inf)  # (t, i, j): min over k, one k at a time
        for k in range(cross.shape[2]):  # elementwise minimum of whole blocks: vectorises
            about_k = cross[:, :, k]  # (t, i)
            np.minimum(worst_turn, about_k[:, None, :] - about_k[:, :, None], out=worst_turn)
        length = np.hypot(x[:, None, :] - x[:, :, None], y[:, None, :] - y[:, :, None])
        edge = (worst_turn + cross >= -1e-9 * length) & (length > 1e-9)
        dist = np.where(edge, -cross / np.where(length > 0, length, 1.0), -np.inf)
        best = dist.reshape(len(x), -1).max(axis=1)
        out[a : a + CHUNK] = np.where(np.isfinite(best), np.maximum(best, 0.0), np.nan)
    out[~some] = np.nan
    return out


class BalanceCheck:
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

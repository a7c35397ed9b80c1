"""Balance: the centre of mass projected on the floor against the support polygon (cm).

The support polygon is the ConvexHull (scipy) of the sole corners in contact (a foot's four
corners count when any of its heel/toe points is in contact). The per-frame value is how
far the CoM lies outside the polygon (hull facet margin, > 0 outside, 0 inside; NaN without
support). Informative: walking and running are dynamically balanced, so no threshold.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from sim.checks.base import CheckResult
from sim.checks.replay import BodyReplay
from sim.thresholds import CheckConfig


def outside_margin(points: np.ndarray, p: np.ndarray) -> float:
    """How far ``p (2,)`` lies outside the convex hull of ``points (K, 2)`` (>= 0), or its
    distance to the nearest point when the points are too few or collinear for a hull."""
    try:
        eq = ConvexHull(points).equations  # rows (nx, ny, offset); inside: n.p + offset <= 0
    except (QhullError, ValueError):
        return float(np.min(np.linalg.norm(points - p, axis=1)))
    return float(max(0.0, np.max(eq[:, :2] @ p + eq[:, 2])))


class Balance:
    name = "balance"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        corners = replay.sole_corners[..., :2]  # (T, 2, 4, 2)
        feet = replay.foot_contact  # (T, 2)
        com = replay.com[:, :2]
        margin = np.full(replay.n_frames, np.nan)
        for t in np.flatnonzero(feet.any(axis=1)):  # one small hull per supported frame
            margin[t] = outside_margin(corners[t, feet[t]].reshape(-1, 2), com[t])
        margin_cm = 100.0 * margin
        supported = np.isfinite(margin_cm)
        outside = supported & (margin_cm > 0)
        return CheckResult(
            name=self.name,
            per_frame={"com_outside_support_cm": margin_cm},
            values={"com_outside_support_frac": float(outside.sum() / max(supported.sum(), 1))},
            flagged=np.zeros(replay.n_frames, dtype=bool),
        )

"""Self-collision: MuJoCo contacts between geoms of two bodies of the humanoid.

MuJoCo already drops parent-child pairs and the pairs the body's MJCF excludes (segments
that touch in the rest pose), so every remaining body-body contact is between non-adjacent
segments. A frame collides when such a contact is deeper than ``self_collision_depth_cm``.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


class SelfCollisionCheck:
    name = "self_collision"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        trace, model = replay.trace, replay.model
        bodies = model.geom_bodyid[trace.contact_geom]  # (N, 2)
        between = (bodies > 0).all(axis=1)
        depth_cm = np.zeros(replay.n_frames)
        np.maximum.at(depth_cm, trace.contact_frame[between], -100.0 * trace.contact_dist[between])
        deep = between & (-100.0 * trace.contact_dist > config.self_collision_depth_cm)
        pairs = Counter(
            tuple(sorted((model.body(a).name, model.body(b).name))) for a, b in bodies[deep]
        )
        colliding = depth_cm > config.self_collision_depth_cm
        return CheckResult(
            name=self.name,
            per_frame={"self_collision_cm": depth_cm},
            values={"self_collision_frac": float(colliding.mean())},
            flagged=colliding,
            details={"pairs": {" / ".join(p): n for p, n in pairs.most_common(10)}},
        )

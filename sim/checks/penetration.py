"""Ground penetration: depth of MuJoCo's deepest floor contact per frame (cm)."""

from __future__ import annotations

import numpy as np

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


class PenetrationCheck:
    name = "penetration"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        depth_cm = 100.0 * replay.trace.floor_penetration
        return CheckResult(
            name=self.name,
            per_frame={"penetration_cm": depth_cm},
            values={
                "penetration_cm_p95": float(np.percentile(depth_cm, 95)),
                "penetration_cm_max": float(depth_cm.max()),
            },
            flagged=depth_cm > config.penetration_cm_p95,
        )

"""Floating: the lowest body point above the floor while nothing supports the body (cm).

A frame floats by the lowest height the body reaches within ``float_window_s`` around it, so
the flight phases of running (ballistic, shorter than the window) do not count.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import minimum_filter1d

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


class FloatingCheck:
    name = "floating"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        height_cm = 100.0 * np.maximum(replay.trace.lowest_point, 0.0)
        window = max(1, int(round(config.float_window_s * replay.fps)) | 1)  # odd, centred
        float_cm = minimum_filter1d(height_cm, window, mode="nearest")
        return CheckResult(
            name=self.name,
            per_frame={"lowest_point_cm": 100.0 * replay.trace.lowest_point, "float_cm": float_cm},
            values={"float_cm_p95": float(np.percentile(float_cm, 95))},
            flagged=float_cm > config.float_cm_p95,
        )

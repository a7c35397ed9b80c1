"""Jitter: jerk of the body positions (m/s^3), third finite difference over frames.

Plain differences, not central ones: a central difference is blind to noise that alternates
every frame (the Nyquist frequency), the very jitter this check is for.
"""

from __future__ import annotations

import numpy as np

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


class JitterCheck:
    name = "jitter"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        pos = replay.trace.body_pos[:, 1:]  # (T, B-1, 3), without the world body
        n = replay.n_frames
        if n < 4:
            jerk = np.zeros(n)
        else:
            third = np.linalg.norm(np.diff(pos, n=3, axis=0), axis=-1).mean(axis=1) * replay.fps**3
            jerk = np.pad(third, (1, 2), mode="edge")  # difference t-1..t+2 centred near t
        return CheckResult(
            name=self.name,
            per_frame={"jerk_m_s3": jerk},
            values={"jitter_m_s3_median": float(np.median(jerk))},
            flagged=jerk > config.jitter_m_s3_median,
        )

"""Foot skating: horizontal speed of a foot's contact points while in contact (cm/s).

Per foot and frame, the mean horizontal speed of its heel/toe points that are in contact.
The clip value is the worse foot's median over its contact frames (a foot that never
touches contributes nothing); ``skate_frac`` is the share of contact frames above
``skate_speed_cm_s``.
"""

from __future__ import annotations

import numpy as np

from sim.checks.base import CheckResult
from sim.checks.replay import SIDES, BodyReplay
from sim.thresholds import CheckConfig


class Skating:
    name = "skating"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        contact = replay.point_contact  # (T, 2, 2)
        speed = 100.0 * np.linalg.norm(replay.sole_velocity[..., :2], axis=-1)  # (T, 2, 2)
        n_in_contact = contact.sum(axis=2)
        with np.errstate(invalid="ignore", divide="ignore"):
            foot_speed = np.where(contact, speed, 0.0).sum(axis=2) / n_in_contact  # (T, 2)
        medians = [
            float(np.median(foot_speed[n_in_contact[:, f] > 0, f]))
            if np.any(n_in_contact[:, f])
            else 0.0
            for f in range(2)
        ]
        in_contact = n_in_contact > 0
        skating = in_contact & (np.nan_to_num(foot_speed) > config.skate_speed_cm_s)
        return CheckResult(
            name=self.name,
            per_frame={f"skate_{side}_cm_s": foot_speed[:, f] for f, side in enumerate(SIDES)},
            values={
                "skate_cm_s_median": max(medians),
                "skate_frac": float(skating.sum() / max(in_contact.sum(), 1)),
            },
            flagged=skating.any(axis=1),
            details={
                f"skate_{side}_cm_s_median": m for side, m in zip(SIDES, medians, strict=True)
            },
        )

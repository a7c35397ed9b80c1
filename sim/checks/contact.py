"""Foot-floor contact (informative): which foot touches the floor, per frame.

Definition in :mod:`sim.thresholds` (height and vertical speed of heel and toe points).
"""

from __future__ import annotations

import numpy as np

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.thresholds import CheckConfig


class FootContactCheck:
    name = "contact"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        contact = replay.foot_contact
        floor_touch = replay.trace.floor_contacts > 0
        return CheckResult(
            name=self.name,
            per_frame={
                "contact_left": contact[:, 0].astype(float),
                "contact_right": contact[:, 1].astype(float),
                "floor_contacts": replay.trace.floor_contacts.astype(float),
            },
            values={
                "contact_frac": float(contact.any(axis=1).mean()),
                "mujoco_floor_contact_frac": float(floor_touch.mean()),
            },
            flagged=np.zeros(replay.n_frames, dtype=bool),
        )

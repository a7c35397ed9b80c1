"""Foot skating: horizontal speed of a foot's contact points while in contact (cm/s).

Per foot and frame, the horizontal speed of its stillest heel/toe point in contact (a foot
rolling heel-to-toe pivots on one point; a sliding foot moves all of them). The clip value is
the worse foot's median over its contact frames (a foot that never touches contributes
nothing); ``skate_frac`` is the share of contact frames above ``skate_speed_cm_s``. A slow
drift during a long stance has a small speed, so each stance (a run of contact frames) also
gets its slide: the horizontal distance its stillest point moved from the first frame to the
last; ``skate_slide_cm_max`` is the largest.
"""

from __future__ import annotations

import numpy as np

from sim.checks.base import CheckResult
from sim.checks.replay import SIDES, BodyReplay
from sim.thresholds import CheckConfig


def contact_runs(contact: np.ndarray) -> np.ndarray:
    """``(R, 2)`` first and last frame of every run of True in ``contact (T,)``."""
    edges = np.diff(np.concatenate([[0], contact.astype(np.int8), [0]]))
    return np.stack([np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1], axis=1)


def stance_slides(points: np.ndarray, contact: np.ndarray) -> list[np.ndarray]:
    """Per foot, ``(R,)`` horizontal slide (m) of the stillest of its points ``(T, 2, P, 2)``
    over each contact run of ``contact (T, 2)``."""
    out = []
    for f in range(contact.shape[1]):
        runs = contact_runs(contact[:, f])
        moved = np.linalg.norm(points[runs[:, 1], f] - points[runs[:, 0], f], axis=-1)
        out.append(moved.min(axis=1) if runs.size else np.zeros(0))
    return out


class Skating:
    name = "skating"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        contact = replay.point_contact  # (T, 2, P)
        speed = 100.0 * np.linalg.norm(replay.sole_velocity[..., :2], axis=-1)  # (T, 2, P)
        n_in_contact = contact.sum(axis=2)
        foot_speed = np.where(contact, speed, np.inf).min(axis=2)  # (T, 2)
        foot_speed[n_in_contact == 0] = np.nan
        slides = stance_slides(replay.sole_points[..., :2], n_in_contact > 0)
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
                "skate_slide_cm_max": 100.0 * max(s.max(initial=0.0) for s in slides),
            },
            flagged=skating.any(axis=1),
            details={
                f"skate_{side}_cm_s_median": m for side, m in zip(SIDES, medians, strict=True)
            },
        )

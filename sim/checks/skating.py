"""Foot skating: horizontal speed of the point of a foot's sole that bears contact (cm/s).

Per foot and frame, the slip velocity of its contact patch: the horizontal velocity of the
stillest point of the patch spanned by its sole points in contact (the heel/toe points; with
two or more in contact, any point on the segment between two of them, whose velocity is
interpolated linearly as on a rigid body). A foot rolling heel-to-toe rests on one point at a
time, and a foot pivoting (turning about the ball, as a basketball pivot does) rests on its
pivot, which does not move, so neither slips; a sliding foot moves every point. The clip value
is the worse foot's median slip speed over its contact frames (a foot that never touches
contributes nothing); ``skate_frac`` is the share of contact frames above ``skate_speed_cm_s``.
A slow drift during a long stance has a small speed, so each stance (a run of contact frames)
also gets its slide: the length of the summed slip velocity over the stance, i.e. how far the
contact moved on the floor beyond rolling and pivoting (the velocity of the point in contact
at each frame, not of a fixed point between the stance's first and last frames: a heel up in
the air at touch-down does not count); ``skate_slide_cm_max`` is the largest.
"""

from __future__ import annotations

import numpy as np

from avatarsim.sim.checks.base import CheckResult
from avatarsim.sim.checks.replay import SIDES, BodyReplay
from avatarsim.sim.thresholds import CheckConfig


def contact_runs(contact: np.ndarray) -> np.ndarray:
    """``(R, 2)`` first and last frame of every run of True in ``contact (T,)``."""
    edges = np.diff(np.concatenate([[0], contact.astype(np.int8), [0]]))
    return np.stack([np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1], axis=1)


def slip_velocity(velocity: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """``(..., 2)`` horizontal velocity of the stillest point of the contact patch, NaN where
    no point is in contact.

    ``velocity (..., P, 2)`` of the sole points, ``contact (..., P)``. The patch is every
    segment between two points in contact (a point alone with itself); along a segment the
    velocity is the linear interpolation of its ends' (exact on a rigid body), so a foot
    turning about any point between its heel and toe has a zero slip there.
    """
    i, j = np.triu_indices(velocity.shape[-2])  # every pair, each point with itself too
    a, b = velocity[..., i, :], velocity[..., j, :]  # (..., Q, 2)
    d = b - a
    dd = np.sum(d * d, axis=-1)
    lam = np.clip(-np.sum(a * d, axis=-1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    w = a + lam[..., None] * d  # stillest point of each segment
    speed = np.where(contact[..., i] & contact[..., j], np.linalg.norm(w, axis=-1), np.inf)
    best = np.take_along_axis(w, speed.argmin(axis=-1)[..., None, None], axis=-2)[..., 0, :]
    return np.where(np.isfinite(speed.min(axis=-1))[..., None], best, np.nan)


def stance_slides(slip: np.ndarray, contact: np.ndarray, fps: float) -> list[np.ndarray]:
    """Per foot, ``(R,)`` slide (m) of its contact over each contact run of
    ``contact (T, 2)``: the length of the slip velocity ``slip (T, 2, 2)`` summed over the
    run (the contact's net displacement on the floor; noise averages out)."""
    out = []
    for f in range(contact.shape[1]):
        runs = contact_runs(contact[:, f])
        moved = [np.linalg.norm(slip[a : b + 1, f].sum(axis=0)) / fps for a, b in runs]
        out.append(np.array(moved))
    return out


class SkatingCheck:
    name = "skating"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        contact = replay.point_contact  # (T, 2, P)
        slip = slip_velocity(replay.sole_velocity[..., :2], contact)  # (T, 2, 2)
        foot_speed = 100.0 * np.linalg.norm(slip, axis=-1)  # (T, 2), NaN without contact
        in_contact = contact.any(axis=2)
        slides = stance_slides(slip, in_contact, replay.fps)
        medians = [
            float(np.median(foot_speed[in_contact[:, f], f])) if np.any(in_contact[:, f]) else 0.0
            for f in range(2)
        ]
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

"""Helpers for activities done in place: feet at home, legs solved onto foot tracks."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator.curves import smooth_cap
from avatarsim.avatar_models.generator.feet import (
    FootGeometry,
    FootTrack,
    pelvis_height_limit,
    planted,
)
from avatarsim.avatar_models.generator.plan import LimbTarget, Scene

# Half-width of the window over which the pelvis lowers ahead of a foot it must reach: wide
# enough that the lowering takes a few tenths of a second (well under 1 g), like a person
# who bends the knees before stepping down or out.
CAP_HALF_WIDTH_S = 0.25


def home_ankles(scene: Scene, width: float = 1.0) -> dict[str, np.ndarray]:
    """``{side: (3,)}`` ankle positions of a relaxed stance, ``width`` times the rest width."""
    out = {}
    for side in "LR":
        rest = scene.rest(f"Bip01 {side} Foot")
        out[side] = np.array([0.0, rest[1] * width, rest[2]])
    return out


def planted_feet(scene: Scene, width: float = 1.0) -> dict[str, FootTrack]:
    geom = FootGeometry.of(scene)
    n = scene.n_frames
    return {
        s: planted(geom, np.broadcast_to(a, (n, 3)).copy())
        for s, a in home_ankles(scene, width).items()
    }


def leg_targets(
    scene: Scene, feet: dict[str, FootTrack], pole: tuple[float, float, float] = (1.0, 0.15, 0.0)
) -> tuple[dict[str, LimbTarget], dict[str, np.ndarray]]:
    """IK targets of both legs onto ``feet`` with the knees pointing along ``pole`` (given for
    the left knee; the right one is mirrored), and the toe joints' local rotations."""
    legs, toes = {}, {}
    for side, track in feet.items():
        p = np.array(pole) * (1.0, 1.0 if side == "L" else -1.0, 1.0)
        legs[side] = LimbTarget(
            track.ankle, np.broadcast_to(p, (scene.n_frames, 3)), track.rotation
        )
        toes[f"Bip01 {side} Toe0"] = track.toe  # about Y: the same on both sides
    return legs, toes


def reachable_root(
    scene: Scene, root: np.ndarray, trunk: np.ndarray, feet: dict[str, FootTrack]
) -> np.ndarray:
    """``root (T, 3)`` lowered where needed so both legs reach their feet (``trunk (T, 3, 3)``
    is the root times pelvis rotation), smoothly (:func:`~.curves.smooth_cap`)."""
    ankles = np.stack([feet[s].ankle for s in "LR"], axis=1)
    out = root.copy()
    limit = pelvis_height_limit(scene, root[:, :2], trunk, ankles)
    out[:, 2] = smooth_cap(root[:, 2], limit, scene.fps, CAP_HALF_WIDTH_S)
    return out

"""CoolMoves applications (§5): motion exaggeration, limb remapping, style sub-libraries.

- Exaggeration (§5.3, "scaling to exaggerate motions of player, thus decreasing the overall
  motion footprint"): each tracked hand's motion about its own centre of motion is scaled
  before matching. The centre is a causal exponential moving average of the head-relative
  hand (time constant ``centre_s``), so the transform also works on a live stream.
- Limb remapping (§5.3, "the user can make use of their hands to run while sitting on a
  chair"): the database is built with the feet as drivers (:data:`FEET_DRIVE`), and the
  hands' motion about their centre is moved to where the feet move about theirs.
- Style (§5.2): a database from the clips of one style only (Bandai: tired, happy, old...;
  the generator: its :data:`~avatar_models.generator.STYLES`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.signal import lfilter

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.library import MotionLibrary
from avatarsim.render_cams import TrackingStream
from avatarsim.synthesis.base import SynthesisError, on_clock, usable_mask
from avatarsim.synthesis.coolmoves.database import (
    FEET_DRIVE,
    HANDS_DRIVE,
    Database,
    Drivers,
    labels,
)

CENTRE_TIME_CONSTANT_S = 1.0
"""Centre of a hand's motion: the average over about the last second (our choice)."""


def _held(values: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``values (T, ...)`` with untracked samples replaced by the last tracked one."""
    last = np.maximum.accumulate(np.where(ok, np.arange(ok.size), 0))
    return values[last]


def motion_centre(relative: np.ndarray, ok: np.ndarray, rate_hz: float, tau_s: float) -> np.ndarray:
    """Causal exponential moving average ``(T, 3)`` of head-relative positions ``(T, 3)``."""
    alpha = 1.0 - np.exp(-1.0 / (tau_s * rate_hz))
    held = _held(relative, ok)
    start = held[0]
    return start + lfilter([alpha], [1.0, alpha - 1.0], held - start, axis=0)


def recentred_hands(
    stream: TrackingStream,
    scale: float,
    targets: dict[str, tuple[str, np.ndarray | None]],
    head: str = "hmd",
    centre_s: float = CENTRE_TIME_CONSTANT_S,
) -> TrackingStream:
    """Hands moved about their centre of motion: ``p' = head + target + scale (p - head - c)``.

    Args:
        targets: per source device, the device name it becomes and the head-relative centre
            ``(3,)`` to move it to (None: its own centre, i.e. only scaling).
    """
    clocked = on_clock(stream)
    rate = float(clocked.meta["rate_hz"])
    ok = usable_mask(clocked)
    h = clocked.device(head)
    names, positions = list(clocked.device_names), clocked.positions.copy()
    for source, (name, target) in targets.items():
        d = clocked.device(source)
        tracked = ok[:, d] & ok[:, h]
        rel = clocked.positions[:, d] - clocked.positions[:, h]
        if not tracked.any():
            continue
        centre = motion_centre(np.where(tracked[:, None], rel, 0.0), tracked, rate, centre_s)
        anchor = centre if target is None else np.asarray(target, float)
        moved = clocked.positions[:, h] + anchor + scale * (rel - centre)
        positions[:, d] = np.where(tracked[:, None], moved, np.nan)
        names[d] = name
    return clocked.replace(
        device_names=tuple(names),
        positions=positions,
        valid=clocked.valid & np.isfinite(positions).all(-1),
        meta={**clocked.meta, "transform": {"scale": scale, "targets": list(targets)}},
    )


def exaggerate(
    stream: TrackingStream, scale: float, drivers: Drivers = HANDS_DRIVE
) -> TrackingStream:
    """The stream with each hand's motion about its centre scaled by ``scale`` (> 1 enlarges)."""
    if not (np.isfinite(scale) and scale > 0):
        raise SynthesisError(f"exaggeration scale must be positive, got {scale!r}")
    targets = {drivers.left: (drivers.left, None), drivers.right: (drivers.right, None)}
    return recentred_hands(stream, scale, targets, drivers.head)


def hands_as_feet(stream: TrackingStream, database: Database, scale: float = 1.0) -> TrackingStream:
    """The hands' motion re-labelled as the feet of a :data:`FEET_DRIVE` database.

    Each hand's motion about its centre (times ``scale``) is placed about the mean
    head-relative position of the matching foot in the database; the result drives a
    :class:`~synthesis.coolmoves.CoolMoves` on that database (running with the hands).
    """
    drv = database.drivers
    if drv.left == HANDS_DRIVE.left:
        raise SynthesisError("limb remapping needs a database built with drivers=FEET_DRIVE")
    feet_centre = database.windows[:, -1].mean(axis=0)  # (2, 3) head-relative
    targets = {
        HANDS_DRIVE.left: (drv.left, feet_centre[0]),
        HANDS_DRIVE.right: (drv.right, feet_centre[1]),
    }
    return recentred_hands(stream, scale, targets, drv.head)


def style_sub_library(
    source: Sequence[Motion] | MotionLibrary, style: str | Sequence[str]
) -> list[Motion]:
    """The motions of ``style`` (one or several) from a library or a list of motions.

    Raises :class:`SynthesisError` when none has that style.
    """
    wanted = {style.lower()} if isinstance(style, str) else {s.lower() for s in style}
    if isinstance(source, MotionLibrary):
        motions = [clip.load() for clip in source.query(style=sorted(wanted))]
    else:
        motions = [m for m in source if str(labels(m)["style"] or "").lower() in wanted]
    if not motions:
        raise SynthesisError(f"no motion of style {sorted(wanted)} in the library")
    return motions


__all__ = [
    "FEET_DRIVE",
    "exaggerate",
    "hands_as_feet",
    "motion_centre",
    "recentred_hands",
    "style_sub_library",
]

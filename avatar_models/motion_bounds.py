"""Physical bounds on motion read from a file: finite but absurd values are bad input.

A finite value can still be no person's motion (a channel of ``1e300``, a unit mix-up of a
million): downstream it becomes a QP without solution, a NaN residual or a picture of
nothing. :func:`check_physical` refuses such a motion with the file, the frame and the
channel, at load time (:func:`avatar_models.formats.load_motion`), so every command that
reads motion gets the same check. Bounds, each far above anything a human body does:

- :data:`MAX_DISTANCE_M`, 1 km from the world origin for any joint: beyond any capture
  volume (the largest, outdoor inertial suits walking a field, span a few hundred metres).
- :data:`MAX_SPEED_M_S`, 100 m/s for any joint: twice the fastest human body segment, the
  hand of a baseball pitcher at ball release (under 47 m/s: the fastest recorded pitch is
  105.8 mph), so marker jitter at high frame rates never trips it (1 cm between frames at
  480 fps is 4.8 m/s); a sprinter's body moves at 12.4 m/s at most.

Rotations are bounded through what they move (the joint speeds of the bones below them), not
by an angular speed: real mocap flips short bones by nearly 180 degrees between two frames
(CMU's clips at 120 fps do), far above any joint's real speed, and between two frames
a rotation turns at most pi, so at 30 fps no angular-speed bound above human peaks (about
7,000 deg/s, the shoulder's internal rotation in baseball pitching: Fleisig et al., Am. J.
Sports Med. 23(2):233-239, 1995) could trip at all.

Speeds are finite differences between consecutive frames (``(T - 1, J)``), so a single
frame's spike shows at full size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.motion import Motion

MAX_DISTANCE_M = 1000.0
MAX_SPEED_M_S = 100.0
AXES = "xyz"


def file_frame(motion: Motion, frame: int) -> int:
    """The 0-based frame of the file that frame ``frame`` of ``motion`` came from (a reader
    that dropped frames records them in ``meta["dropped_frames"]["frames"]``)."""
    dropped = np.asarray(motion.meta.get("dropped_frames", {}).get("frames", []), dtype=int)
    kept = np.setdiff1d(np.arange(motion.n_frames + dropped.size), dropped)
    return int(kept[frame])


def _first(bad: np.ndarray) -> tuple[int, ...] | None:
    """Index of the first True of ``bad`` (frame-major), None when there is none."""
    hits = np.argwhere(bad)
    return None if hits.size == 0 else tuple(int(i) for i in hits[0])


def _unit_first(motion: Motion, source: str | Path, error: MotionValueError) -> None:
    """Raise the height check's error (it names the unit that fits) when the body is no
    person's height: a wrong unit explains a bound passed; else ``error``."""
    from avatarsim.avatar_models.measure import check_plausible_height

    try:
        check_plausible_height(motion)
    except MotionValueError as wrong_unit:
        raise MotionValueError(f"{source}: {wrong_unit}") from None
    raise error


def check_physical(motion: Motion, source: str | Path, from_frame: int = 0) -> None:
    """Refuse ``motion`` (read from ``source``) when a joint is farther than
    :data:`MAX_DISTANCE_M` from the origin, or moves faster than :data:`MAX_SPEED_M_S`
    between two frames (module docstring), from frame ``from_frame`` on (1: a rest pose kept
    ahead of the take jumps to its first pose in one frame). A body of no person's height
    gets the height check's error instead (a wrong unit, named there).

    Raises:
        MotionValueError: naming ``source``, the file's frame and the joint channel.
    """
    names = motion.skeleton.names
    with np.errstate(over="ignore", invalid="ignore"):
        pos = motion.global_positions()  # (T, J, 3)
        far = ~(np.abs(pos) <= MAX_DISTANCE_M)
        if (hit := _first(far)) is not None:
            t, j, a = hit
            _unit_first(
                motion,
                source,
                MotionValueError(
                    f"{source}: frame {file_frame(motion, t)} (from 0), joint {names[j]!r} world "
                    f"{AXES[a]} (Z up) = {pos[t, j, a]:.4g} m, more than {MAX_DISTANCE_M:g} m "
                    "from the origin: no capture volume is that large (a wrong unit or a corrupt "
                    "value?)"
                ),
            )
        if motion.n_frames < 2:
            return
        speed = np.linalg.norm(np.diff(pos, axis=0), axis=-1) * motion.fps  # (T-1, J)
        speed[:from_frame] = 0.0
        if (hit := _first(~(speed <= MAX_SPEED_M_S))) is not None:
            t, j = hit
            _unit_first(
                motion,
                source,
                MotionValueError(
                    f"{source}: frame {file_frame(motion, t + 1)} (from 0), joint {names[j]!r} "
                    f"moves at {speed[t, j]:.4g} m/s from the frame before, faster than any body "
                    f"part ({MAX_SPEED_M_S:g} m/s; a corrupt value or a wrong frame rate?)"
                ),
            )

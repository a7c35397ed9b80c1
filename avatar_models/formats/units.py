"""Length units of motion files and the Y-up -> Z-up change of axes.

``UNITS`` maps a unit name to metres per file unit. ``"cmu"`` is the CMU ASF length unit:
the ASF files store ``length 1/0.45`` with lengths in inches, so one unit is
``0.0254 / 0.45 = 0.056444`` m (CMU mocap FAQ; dm_control's CMU humanoid uses the same factor).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError

UNITS: dict[str, float] = {
    "m": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "inch": 0.0254,
    "cmu": 0.056444,
}

# Y-up (facing +Z, left +X) -> Z-up (facing +X, left +Y): new = C @ old, a proper rotation.
Y_UP_TO_Z_UP = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])

# A standing adult is 1.0-2.5 m tall; a unit is plausible if it puts the skeleton in there.
HUMAN_HEIGHT_M = (1.0, 2.5)
TYPICAL_HEIGHT_M = 1.7


def unit_scale(unit: str | float, path: object = None) -> float:
    """Metres per file unit for a unit name in :data:`UNITS` or a positive number."""
    if isinstance(unit, str):
        if unit not in UNITS:
            raise MotionFormatError(
                f"unknown unit {unit!r}; use one of {', '.join(UNITS)} or metres per unit", path
            )
        return UNITS[unit]
    scale = float(unit)
    if not (np.isfinite(scale) and scale > 0):
        raise MotionFormatError(f"unit scale must be a positive number, got {unit!r}", path)
    return scale


def detect_unit(height_in_units: float, path: object = None) -> tuple[str, float]:
    """The named unit that makes ``height_in_units`` a human height, nearest to 1.7 m.

    Raises :class:`MotionFormatError` (asking for ``--unit``) when no unit gives 1.0-2.5 m.
    """
    lo, hi = HUMAN_HEIGHT_M
    if not (np.isfinite(height_in_units) and height_in_units > 0):
        raise MotionFormatError(
            "the skeleton has no size (its bones are all zero length), so no unit fits", path
        )
    fits = [
        (abs(np.log(height_in_units * s / TYPICAL_HEIGHT_M)), name, s)
        for name, s in UNITS.items()
        if np.isfinite(height_in_units) and lo <= height_in_units * s <= hi
    ]
    if not fits:
        raise MotionFormatError(
            f"cannot guess the length unit: the skeleton is {height_in_units:.4g} units tall and "
            f"no unit ({', '.join(UNITS)}) makes that {lo}-{hi} m; give the unit with --unit "
            "(a name or metres per unit; from Python: unit=)",
            path,
        )
    _, name, scale = min(fits)
    return name, scale

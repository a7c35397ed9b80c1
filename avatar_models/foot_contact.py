"""Foot-contact labelling: which feet (or foot points) touch the floor, frame by frame.

One test for every user, each with its own thresholds and its own notion of height and speed
(the physics checks label sole points with central-difference speeds, the synthesiser labels
ankles causally, retargeting labels stance from the toe height and the ankle's speed). A point
is in contact when it is low, above a floor level by less than ``max_height``, and, where
speeds are given, slow: vertically slower than ``max_vertical_speed`` (the vertical speed
only, as UHC, Luo et al. 2021, and PhysDiff, Yuan et al. 2023, label contacts, so that a foot
sliding on the floor still counts and its sliding can be measured) and horizontally slower
than ``max_horizontal_speed`` (faster is a swing, not a stance). :func:`lasting` drops
contacts shorter than a minimum duration.

Shapes: ``T`` frames, ``...`` any trailing axes (feet, points per foot).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage


def contact_mask(
    height: np.ndarray,
    max_height: float,
    floor: np.ndarray | float = 0.0,
    vertical_velocity: np.ndarray | None = None,
    max_vertical_speed: float = np.inf,
    horizontal_speed: np.ndarray | None = None,
    max_horizontal_speed: float = np.inf,
) -> np.ndarray:
    """``(T, ...)`` contact labels (module docstring).

    Args:
        height: ``(T, ...)`` heights of the feet or foot points (m).
        max_height: contact height above ``floor`` (m).
        floor: height a point has standing on the floor, broadcast against ``height``.
        vertical_velocity: ``(T, ...)`` signed vertical velocity (m/s); ``None``: no test.
        max_vertical_speed: contact bound on its magnitude (m/s).
        horizontal_speed: ``(T, ...)`` horizontal speed (m/s); ``None``: no test.
        max_horizontal_speed: contact bound on it (m/s).
    """
    contact = height - floor < max_height
    if vertical_velocity is not None:
        contact &= np.abs(vertical_velocity) < max_vertical_speed
    if horizontal_speed is not None:
        contact &= horizontal_speed < max_horizontal_speed
    return contact


def lasting(contact: np.ndarray, min_frames: int) -> np.ndarray:
    """``contact (T, ...)`` without the runs (along T, per trailing index) shorter than
    ``min_frames``; longer runs are kept whole (binary opening along time)."""
    if min_frames <= 1:
        return contact
    structure = np.ones((min_frames,) + (1,) * (contact.ndim - 1), dtype=bool)
    return ndimage.binary_opening(contact, structure=structure)


def horizontal_speed(positions: np.ndarray, fps: float) -> np.ndarray:
    """``(T, ...)`` horizontal speed (m/s) of ``positions (T, ..., 3)`` by central
    differences (one-sided at the ends)."""
    return np.linalg.norm(np.gradient(positions[..., :2], 1.0 / fps, axis=0), axis=-1)

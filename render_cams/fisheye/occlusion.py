"""A controller camera against or inside the body: what it records, and the per-frame flag.

Controllers swing against the thighs, the chest in a boxing guard, or the other arm, and a
real camera on one then records what its lens is pressed into: almost nothing. The recording
goes on; those frames are dark and useless, and a pipeline (ControllerPose filters unusable
frames, §4.2) has to recognise them. Two cases, decided from the geometry of each frame:

- **Centre inside the body** (the camera centre lies inside a body segment,
  :func:`~render_cams.fisheye.rig.inside_body`): the lens is covered by flesh or cloth and no
  scene light reaches it. The frame is the sensor's dark frame: black level
  :data:`DARK_LEVEL` plus read noise :data:`DARK_NOISE` (grey levels, seeded), range 0 (no
  surface can be measured), no keypoint visible. ``lens_blocked`` is 1.
- **Lens against the body**: surfaces closer than :data:`BLOCKING_RANGE_M` to the camera
  centre are in the shadow of the controller and the hand holding it (and far inside the
  near focus limit of a small fixed-focus lens): their pixels are darkened,
  ``colour * (range / BLOCKING_RANGE_M) ** 2`` (the share of the room's light the controller
  leaves them falls like the solid angle it covers). ``lens_blocked`` is the fraction of the
  image circle they cover.

A frame is ``occluded`` when ``lens_blocked >= OCCLUDED_FRACTION``: at least half the image
circle shows nothing but the body at touching distance (or nothing at all). The record also
keeps the frame's ``mean_luminance`` (0-255, inside the image circle): an occluded frame has
a mean far below :data:`render_cams.fisheye.bad_frames.BLACK_LEVEL`, so the image-only
detector of :mod:`render_cams.fisheye.bad_frames` flags it as a black frame too.

The thresholds are modelling choices, not measurements: 5 cm is about the size of the
controller's ring and of the hand around the grip, the shadow they cast; half the image
circle is where the frame can no longer show the body the cameras are meant to see.
"""

from __future__ import annotations

import numpy as np

BLOCKING_RANGE_M = 0.05
"""Surfaces closer than this to the camera centre block (darken) the lens."""
OCCLUDED_FRACTION = 0.5
"""Share of the image circle blocked from which a frame counts as occluded."""
DARK_LEVEL = 4.0
"""Mean grey level (0-255) of a covered camera's frame (black level)."""
DARK_NOISE = 2.0
"""Standard deviation (grey levels) of a covered camera's read noise."""


def dark_frame(height: int, width: int, rng: np.random.Generator) -> np.ndarray:
    """``(H, W, 3)`` uint8 frame of a camera whose lens is covered: black level plus read
    noise (the same on the three channels, as the analog receivers show snow in grey)."""
    noise = rng.normal(DARK_LEVEL, DARK_NOISE, (height, width))
    return np.repeat(np.clip(np.rint(noise), 0, 255).astype(np.uint8)[..., None], 3, axis=2)


def block_lens(
    colour: np.ndarray, range_m: np.ndarray, image_circle: np.ndarray
) -> tuple[np.ndarray, float]:
    """Darken the pixels that see a surface within :data:`BLOCKING_RANGE_M`; return the frame
    and ``lens_blocked``, the fraction of the image circle they cover.

    Args:
        colour: ``(H, W, 3)`` uint8 rendered frame.
        range_m: ``(H, W)`` range along each pixel's ray (0 where nothing was hit).
        image_circle: ``(H, W)`` bool, the pixels the lens images.
    """
    near = image_circle & (range_m > 0) & (range_m < BLOCKING_RANGE_M)
    if not near.any():
        return colour, 0.0
    shade = np.where(near, (range_m / BLOCKING_RANGE_M) ** 2, 1.0)[..., None]
    darkened = np.rint(colour * shade).astype(np.uint8)
    return darkened, float(near.sum() / max(int(image_circle.sum()), 1))


def mean_luminance(colour: np.ndarray, image_circle: np.ndarray) -> float:
    """Mean grey level (0-255) of ``colour`` ``(H, W, 3)`` inside the image circle."""
    grey = colour.astype(np.float32).mean(axis=-1)
    return float(grey[image_circle].mean()) if image_circle.any() else 0.0

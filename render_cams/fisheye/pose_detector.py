"""The 2D pose detector protocol: what ControllerPose's detector step (§4.3, OpenPose v1.7 in
the paper) reads and reports, so that any detector plugs into the same pipeline.

A :class:`PoseDetector` takes one RGB image and returns :class:`Keypoints2D`: ``body17``
pixels, a confidence per joint and whether a person was found. Two implementations:

- :class:`render_cams.fisheye.blazepose.BlazePoseDetector` (``"blazepose"``): MediaPipe
  BlazePose on the pixels, standing in for the paper's OpenPose v1.7;
- :class:`render_cams.fisheye.detector.ErrorModelDetector` (``"error-model"``): a fast
  approximation that ignores the pixels and perturbs the exact projections.

Both receive the image's :class:`ViewTruth` (the exact projections of the joints into that
image, from the renderer's geometry): the error model needs it, a real detector ignores it.
Pixels follow OpenCV: integer coordinates at pixel centres, ``u`` right, ``v`` down.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.body17 import BODY17

N_JOINTS = len(BODY17)


class DetectorError(AvatarsimError, ValueError):
    """A detector given an image or truth it cannot read (shape, dtype), or not installed."""


@dataclass(frozen=True)
class ViewTruth:
    """The exact body17 keypoints of one image (ground truth, never sensor output).

    Attributes:
        uv: ``(17, 2)`` exact pixels (meaningless where not ``in_image``).
        in_image: ``(17,)`` bool: the joint projects inside the image.
        visible: ``(17,)`` bool: not hidden behind other surfaces.
        score: ``(17,)`` visibility score in ``[0, 1]``
            (:func:`render_cams.fisheye.keypoints.confidence`).
    """

    uv: np.ndarray
    in_image: np.ndarray
    visible: np.ndarray
    score: np.ndarray


@dataclass(frozen=True)
class Keypoints2D:
    """What a detector reported on one image.

    Attributes:
        uv: ``(17, 2)`` body17 pixels; ``(0, 0)`` where not ``detected``.
        confidence: ``(17,)`` in ``[0, 1]``; 0 where not ``detected``.
        detected: ``(17,)`` bool: the joint was reported.
        person: a person was found (no joint is reported otherwise).
        detector: the detector's name (``"blazepose"``, ``"error-model"``, ...).
    """

    uv: np.ndarray
    confidence: np.ndarray
    detected: np.ndarray
    person: bool
    detector: str


@runtime_checkable
class PoseDetector(Protocol):
    """A 2D body pose detector on RGB images (module docstring)."""

    name: str

    def detect(self, image: np.ndarray, truth: ViewTruth, rng: np.random.Generator) -> Keypoints2D:
        """body17 keypoints of the person in ``image`` ``(H, W, 3)`` uint8 RGB, whose exact
        keypoints are ``truth``; ``rng`` for detectors that draw."""
        ...


def check_image(image: np.ndarray) -> np.ndarray:
    """``image`` as a C-contiguous ``(H, W, 3)`` uint8 RGB array.

    Raises:
        DetectorError: another shape or dtype.
    """
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8 or image.size == 0:
        raise DetectorError(
            f"a detector reads (H, W, 3) uint8 RGB images, got {image.shape} {image.dtype}"
        )
    return np.ascontiguousarray(image)


def no_person(detector: str) -> Keypoints2D:
    """The report of a detector that found nobody."""
    return Keypoints2D(
        np.zeros((N_JOINTS, 2)), np.zeros(N_JOINTS), np.zeros(N_JOINTS, bool), False, detector
    )

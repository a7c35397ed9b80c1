"""A 2D detector's accuracy against the exact keypoints of the same image: per-joint error in
pixels and PCK, the share of joints within a fraction of the person's torso height.

PCK (percentage of correct keypoints) at ``0.2`` of the torso size, the threshold of the Leeds
Sports Pose benchmark's PCK@0.2 (MPII's PCKh uses the head size instead). Torso height here
is the exact neck-to-pelvis distance in the image. A joint counts when its exact projection
is in the image; a joint the detector did not report is wrong.

:func:`mirror_tolerant` also forgives a whole-body left/right swap (the report mirrored by
``body17.MIRROR`` when that scores better): a detector that takes a person's back for the
front, as on a body without a face, reports the left limbs as the right ones, and PCK alone
cannot tell that from joints in the wrong places.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from avatarsim.avatar_models.body17 import INDEX, MIRROR
from avatarsim.render_cams.fisheye.pose_detector import Keypoints2D, ViewTruth

PCK_FRACTION = 0.2


def torso_height_px(uv: np.ndarray) -> np.ndarray:
    """``(...)`` neck-to-pelvis distance of body17 pixels ``uv`` ``(..., 17, 2)``."""
    return np.linalg.norm(uv[..., INDEX["neck"], :] - uv[..., INDEX["pelvis"], :], axis=-1)


def keypoint_errors(detection: Keypoints2D, truth: ViewTruth) -> np.ndarray:
    """``(17,)`` pixel distance of each reported joint from its exact keypoint; NaN where the
    joint was not reported or is not in the image."""
    error = np.linalg.norm(detection.uv - truth.uv, axis=-1)
    return np.where(detection.detected & truth.in_image, error, np.nan)


def pck(detection: Keypoints2D, truth: ViewTruth, fraction: float = PCK_FRACTION) -> np.ndarray:
    """``(17,)`` 1.0 where a joint in the image was reported within ``fraction`` of the torso
    height of its exact keypoint, 0.0 where it was not (missed or too far), NaN where it is
    not in the image (module docstring)."""
    error = np.linalg.norm(detection.uv - truth.uv, axis=-1)
    hit = detection.detected & (error <= fraction * torso_height_px(truth.uv))
    return np.where(truth.in_image, hit.astype(float), np.nan)


def mirrored(detection: Keypoints2D) -> Keypoints2D:
    """``detection`` with every left joint reported as the right one and back."""
    return replace(
        detection,
        uv=detection.uv[MIRROR],
        confidence=detection.confidence[MIRROR],
        detected=detection.detected[MIRROR],
    )


def mirror_tolerant(detection: Keypoints2D, truth: ViewTruth) -> Keypoints2D:
    """``detection`` or its :func:`mirrored` report, whichever has the higher :func:`pck`
    (``detection`` on a tie)."""
    flipped = mirrored(detection)
    better = np.nansum(pck(flipped, truth)) > np.nansum(pck(detection, truth))
    return flipped if better else detection

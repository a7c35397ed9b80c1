"""The 2D pose pipeline of one controller from its pixels (ControllerPose §4.3): a detector
on the composite image, the torso-normal view warped from the composite image by the 4-point
transform of the *detected* shoulders and hips, the detector again on that warped image, and
its keypoints mapped back into the composite.

The paper: "using the resulting shoulder and hip keypoints, we create torso-normal-aligned
views using a four-point perspective transform ... we use this to produce two more 2D pose
estimates". The transform is :func:`render_cams.fisheye.torso_view.torso_view` (the detected
corners onto a frontal torso), the warp ``cv2.warpPerspective``
(:meth:`~render_cams.fisheye.torso_view.TorsoView.warp`). The same steps on exact keypoints,
batched, are :mod:`render_cams.fisheye.pose2d`. Works with any
:class:`~render_cams.fisheye.pose_detector.PoseDetector`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.fisheye.pose2d import inside
from avatarsim.render_cams.fisheye.pose_detector import (
    Keypoints2D,
    PoseDetector,
    ViewTruth,
    no_person,
)
from avatarsim.render_cams.fisheye.torso_view import TorsoView, apply_homography, torso_view


@dataclass(frozen=True)
class PixelViews:
    """One controller's two views of one frame, as the detector saw them.

    Attributes:
        composite: ``(h, w, 3)`` uint8 the composite image.
        composite_detection: the detector's report on ``composite``.
        torso: the torso-normal view built from ``composite_detection`` (``H`` ``(3, 3)``).
        torso_image: ``(h, w, 3)`` uint8 the warped composite; None without a view.
        torso_truth: the exact keypoints in the torso view (None without a view).
        torso_detection: the detector's report on ``torso_image`` (nobody without a view).
        torso_in_composite: ``(17, 2)`` ``torso_detection``'s pixels mapped back into the
            composite by the inverse transform ((0, 0) where not detected).
    """

    composite: np.ndarray
    composite_detection: Keypoints2D
    torso: TorsoView
    torso_image: np.ndarray | None
    torso_truth: ViewTruth | None
    torso_detection: Keypoints2D
    torso_in_composite: np.ndarray


def moved_truth(truth: ViewTruth, H: np.ndarray, width: int, height: int) -> ViewTruth:
    """``truth`` moved by the homography ``H`` ``(3, 3)`` into a ``width`` x ``height`` view."""
    uv = apply_homography(H, np.nan_to_num(truth.uv))
    in_image = truth.in_image & inside(uv, width, height)
    return ViewTruth(uv, in_image, truth.visible & in_image, truth.score)


def pixel_views(
    composite: np.ndarray,
    truth: ViewTruth,
    detector: PoseDetector,
    rng: np.random.Generator,
) -> PixelViews:
    """Detect on ``composite`` ``(h, w, 3)`` uint8 (exact keypoints ``truth``), warp it into
    the torso-normal view of the detected shoulders and hips, detect again there and map
    those keypoints back (module docstring)."""
    first = detector.detect(composite, truth, rng)
    view = torso_view(first.uv, first.detected)
    height, width = composite.shape[:2]
    if not bool(view.valid):
        nobody = no_person(first.detector)
        return PixelViews(composite, first, view, None, None, nobody, nobody.uv)
    warped = view.warp(composite)
    moved = moved_truth(truth, view.H, width, height)
    again = detector.detect(warped, moved, rng)
    back = apply_homography(np.linalg.inv(view.H), again.uv)
    back = np.where(again.detected[:, None], back, 0.0)
    return PixelViews(composite, first, view, warped, moved, again, back)

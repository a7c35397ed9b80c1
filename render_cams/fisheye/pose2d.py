"""The 2D pose pipeline of one controller's camera pair (ControllerPose §4.2-4.3), on
keypoints: what the detector would report on the composite and on the torso-normal view.

Per frame: the two cameras' frames that the image filter kept (§4.2) are stitched; the body's
joints land on the composite where their rays meet the stitch surface
(:meth:`StitchParams.to_composite`), from the camera that sees each joint best (highest
visibility score); the detector error model (:mod:`render_cams.fisheye.detector`) reports
the composite's keypoints (§4.3 "we extract 2D pose estimates of the user" from the
composite); the torso-normal view is built from the *reported* shoulders and hips alone
(:mod:`render_cams.fisheye.torso_view`), the joints are moved into it by its transform, and
the detector reports them again there (§4.3 "we use this to produce two more 2D pose
estimates"). No view where the detector did not report all four torso corners.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.fisheye.detector import Detection, ErrorModelDetector
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.rig import ControllerCamera, camera_pairs
from avatarsim.render_cams.fisheye.stitch import StitchParams, stitch_params
from avatarsim.render_cams.fisheye.torso_view import TorsoView, apply_homography, torso_view


@dataclass(frozen=True)
class CompositeKeypoints:
    """Where the body's joints are in a controller's composite, over ``T`` frames.

    Attributes:
        uv: ``(T, 17, 2)`` composite pixels (meaningless where not ``in_image``).
        in_image: ``(T, 17)`` bool: a kept camera sees the joint and it lies in the composite.
        visible: ``(T, 17)`` bool: not occluded in the camera it is taken from.
        score: ``(T, 17)`` visibility score in that camera
            (:func:`render_cams.fisheye.keypoints.confidence`).
    """

    uv: np.ndarray
    in_image: np.ndarray
    visible: np.ndarray
    score: np.ndarray


@dataclass(frozen=True)
class ControllerPose2D:
    """The detector's view of one controller over ``T`` frames.

    Attributes:
        params: the pair's stitch parameters (the composite's geometry).
        composite: exact joints in the composite.
        composite_detection: what the detector reported on the composite.
        torso: ``(T,)`` torso-normal views built from ``composite_detection``.
        torso_uv: ``(T, 17, 2)`` exact joints in the torso view.
        torso_detection: what the detector reported in the torso view.
    """

    params: StitchParams
    composite: CompositeKeypoints
    composite_detection: Detection
    torso: TorsoView
    torso_uv: np.ndarray
    torso_detection: Detection


def inside(uv: np.ndarray, width: int, height: int) -> np.ndarray:
    """``(...)`` bool: pixels ``uv`` ``(..., 2)`` inside a ``width`` x ``height`` image."""
    with np.errstate(invalid="ignore"):
        return (
            (uv[..., 0] > -0.5)
            & (uv[..., 0] < width - 0.5)
            & (uv[..., 1] > -0.5)
            & (uv[..., 1] < height - 0.5)
        )


def composite_keypoints(
    params: StitchParams,
    uv: np.ndarray,
    in_image: np.ndarray,
    visible: np.ndarray,
    score: np.ndarray,
    usable: np.ndarray,
) -> CompositeKeypoints:
    """The joints in the composite of a camera pair.

    Args:
        uv: ``(T, 2, 17, 2)`` exact pixels in each camera of the pair.
        in_image, visible: ``(T, 2, 17)`` bool; score: ``(T, 2, 17)``.
        usable: ``(T, 2)`` bool: the frame passed the image filter.
    """
    n_cams = uv.shape[1]
    comp = np.stack([params.to_composite(c, uv[:, c]) for c in range(n_cams)], axis=1)
    cyl = params.cylinder
    seen = in_image & usable[..., None] & inside(comp, cyl.width, cyl.height)
    best = np.argmax(np.where(seen, score, -1.0), axis=1)[:, None]  # (T, 1, 17)
    return CompositeKeypoints(
        uv=np.take_along_axis(comp, best[..., None], axis=1)[:, 0],
        in_image=seen.any(axis=1),
        visible=np.take_along_axis(visible, best, axis=1)[:, 0],
        score=np.take_along_axis(score, best, axis=1)[:, 0],
    )


def controller_pose2d(
    params: StitchParams,
    detector: ErrorModelDetector,
    composite: CompositeKeypoints,
    rng: np.random.Generator,
) -> ControllerPose2D:
    """Detect on the composite, build the torso-normal views from the reported torso
    corners, detect again there (module docstring)."""
    detection = detector.detect_projected(
        composite.uv, composite.in_image, composite.visible, composite.score, rng
    )
    view = torso_view(detection.uv, detection.detected)
    torso_uv = apply_homography(view.H, np.nan_to_num(composite.uv))
    cyl = params.cylinder
    in_view = view.valid[:, None] & composite.in_image & inside(torso_uv, cyl.width, cyl.height)
    again = detector.detect_projected(torso_uv, in_view, composite.visible, composite.score, rng)
    return ControllerPose2D(params, composite, detection, view, torso_uv, again)


def controller_views(
    model: FisheyeModel,
    cameras: Sequence[ControllerCamera],
    uv: np.ndarray,
    in_image: np.ndarray,
    visible: np.ndarray,
    score: np.ndarray,
    usable: np.ndarray,
    detector: ErrorModelDetector,
    rng: np.random.Generator,
) -> dict[str, ControllerPose2D]:
    """:func:`controller_pose2d` of every controller with two of ``cameras`` (lens
    ``model``), from every camera's exact pixels ``uv`` ``(T, C, 17, 2)``, ``in_image``,
    ``visible`` ``(T, C, 17)`` bool, ``score`` ``(T, C, 17)`` and ``usable`` ``(T, C)`` bool
    (passed the image filter)."""
    views = {}
    for controller, pair in camera_pairs(cameras).items():
        params = stitch_params(model, [cameras[c] for c in pair])
        composite = composite_keypoints(
            params,
            uv[:, pair],
            in_image[:, pair],
            visible[:, pair],
            score[:, pair],
            usable[:, pair],
        )
        views[controller] = controller_pose2d(params, detector, composite, rng)
    return views

"""``body17`` 2D keypoints of a fisheye camera: projection, visibility, visibility score.

Projection uses the camera's own model (:meth:`FisheyeModel.project`, equal to
``cv2.fisheye.projectPoints``), vectorised over frames and joints. A joint is *visible* when it
projects inside the image and the rendered range at its pixel is not shorter than the joint's
range minus its own depth along that ray (a joint sits inside its limbs, so the surface seen
there is nearer by the ray's path through them,
:func:`render_cams.fisheye.line_of_sight.own_depth`): otherwise something else, usually the
user's own arm or body, is in front of it.

Confidence is a heuristic of what a 2D detector reports (ControllerPose §4.3 feeds OpenPose
confidences to its network): 1 at the image centre falling to 0.5 at the 90 deg image
circle, where the lens compresses the body most, and 0.1 for occluded joints. It is the
visibility score the detector error model (:mod:`render_cams.fisheye.detector`) starts from.
"""

from __future__ import annotations

import numpy as np

from avatarsim.render_cams.fisheye.model import HALF_PI, FisheyeModel

OCCLUDED_CONFIDENCE = 0.1
RIM_CONFIDENCE = 0.5
DEPTH_SLACK_M = 0.03  # rasterisation and tessellation error of the rendered range


def world_to_camera(camera_to_world: np.ndarray) -> np.ndarray:
    """``(..., 4, 4)`` inverse of rigid poses ``(..., 4, 4)``."""
    rot = camera_to_world[..., :3, :3]
    out = np.zeros_like(camera_to_world)
    out[..., :3, :3] = np.swapaxes(rot, -1, -2)
    out[..., :3, 3] = -np.einsum("...ba,...b->...a", rot, camera_to_world[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def project_joints(
    model: FisheyeModel, camera_to_world: np.ndarray, joints: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixels ``(T, J, 2)``, in-image mask ``(T, J)`` and range ``(T, J)`` (metres) of world
    joints ``(T, J, 3)`` seen by cameras at ``camera_to_world`` ``(T, 4, 4)``."""
    w2c = world_to_camera(np.asarray(camera_to_world, float))
    cam = np.einsum("tab,tjb->tja", w2c[:, :3, :3], joints) + w2c[:, None, :3, 3]
    uv, in_image = model.project(cam)
    return uv, in_image, np.linalg.norm(cam, axis=-1)


def visibility(
    uv: np.ndarray,
    in_image: np.ndarray,
    joint_range: np.ndarray,
    range_image: np.ndarray,
    depth: np.ndarray,
) -> np.ndarray:
    """``(J,)`` bool: joints of one frame not hidden behind other surfaces.

    Args:
        uv, in_image, joint_range: one frame of :func:`project_joints` (``(J, 2)``, ``(J,)``).
        range_image: ``(H, W)`` rendered range (0 where nothing was hit).
        depth: ``(J,)`` each joint's own depth along its ray
            (:func:`render_cams.fisheye.line_of_sight.own_depth`).
    """
    h, w = range_image.shape
    col = np.clip(np.rint(uv[:, 0]).astype(int), 0, w - 1)
    row = np.clip(np.rint(uv[:, 1]).astype(int), 0, h - 1)
    seen = range_image[row, col]
    nearest_allowed = joint_range - depth - DEPTH_SLACK_M
    return in_image & ((seen == 0) | (seen >= nearest_allowed))


def confidence(model: FisheyeModel, uv: np.ndarray, visible: np.ndarray) -> np.ndarray:
    """``(...)`` detector-like confidence of keypoints ``uv`` ``(..., 2)`` (module docstring)."""
    theta = np.nan_to_num(model.angle_of_pixels(uv), nan=HALF_PI)
    rim = 1.0 - (1.0 - RIM_CONFIDENCE) * (theta / HALF_PI) ** 2
    return np.where(visible, rim, OCCLUDED_CONFIDENCE)

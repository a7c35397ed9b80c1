"""Torso-normal-aligned views by a four-point perspective transform (ControllerPose §4.3).

The paper re-detects 2D pose in views rectified toward the torso plane ("using the resulting
shoulder and hip keypoints, we create torso-normal-aligned views using a four-point
perspective transform"), where the lower body is more proportionally correct. Here the
view is that of a virtual pinhole camera at the same centre turned (by the smallest
rotation) to look along the torso normal: its four destination points are where the two
shoulders and two hips land in that camera, shifted so their centroid stays where it was in
the source image, and ``cv2.getPerspectiveTransform`` of source to destination is the
transform. As both cameras share their centre, the transform is the rotation homography
``K R^T K^-1`` (plus the shift) for every point, on the torso plane or not; a torso already
facing the camera gives the identity.

Works on pinhole images: undistort the fisheye first
(:func:`render_cams.fisheye.stitch.undistortion_maps`).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from avatar_models import AvatarsimError
from avatar_models.body17 import INDEX

TORSO_CORNERS = ("l_shoulder", "r_shoulder", "r_hip", "l_hip")  # the four points, in order


class TorsoViewError(AvatarsimError, ValueError):
    """The torso is degenerate or not in front of the camera."""


def torso_normal(joints: np.ndarray) -> np.ndarray:
    """``(..., 3)`` unit normal of the torso pointing out of the chest, from body17 joints
    ``(..., 17, 3)``: (left - right shoulder) x (neck - pelvis); +X for the rest pose (left
    +Y, up +Z). Rotation-invariant, so any frame (world or camera) works."""
    across = joints[..., INDEX["l_shoulder"], :] - joints[..., INDEX["r_shoulder"], :]
    up = joints[..., INDEX["neck"], :] - joints[..., INDEX["pelvis"], :]
    normal = np.cross(across, up)
    norm = np.linalg.norm(normal, axis=-1, keepdims=True)
    if np.any(norm < 1e-9):
        raise TorsoViewError("shoulder line parallel to the spine: no torso normal")
    return normal / norm


@dataclass(frozen=True)
class TorsoView:
    """A torso-normal-aligned view of a pinhole image.

    Attributes:
        H: ``(3, 3)`` perspective transform, source pixels -> view pixels.
        src, dst: ``(4, 2)`` the shoulders and hips (``TORSO_CORNERS``) in the source image
            and in the view.
        rotation: ``(3, 3)`` virtual camera axes (columns) in the source camera frame.
        normal: ``(3,)`` torso normal in the camera frame.
    """

    H: np.ndarray
    src: np.ndarray
    dst: np.ndarray
    rotation: np.ndarray
    normal: np.ndarray

    def warp(self, image: np.ndarray) -> np.ndarray:
        """The view of ``image`` ``(h, w[, c])`` by ``cv2.warpPerspective``, same size."""
        return cv2.warpPerspective(image, self.H, (image.shape[1], image.shape[0]))


def pinhole(K: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(..., 2)`` pixels of camera-frame points ``(..., 3)`` through camera matrix K."""
    p = np.asarray(points, float) @ np.asarray(K, float).T
    return p[..., :2] / p[..., 2:]


def torso_view(K: np.ndarray, joints_cam: np.ndarray) -> TorsoView:
    """The torso-normal-aligned view of a pinhole camera ``K`` ``(3, 3)`` seeing body17
    joints ``joints_cam`` ``(17, 3)`` (camera frame, OpenCV axes).

    Raises:
        TorsoViewError: a torso corner behind the camera, or seen edge-on (the rotated
            camera would have it behind).
    """
    joints_cam = np.asarray(joints_cam, float)
    corners = joints_cam[[INDEX[n] for n in TORSO_CORNERS]]
    if np.any(corners[:, 2] <= 0):
        raise TorsoViewError("a shoulder or hip is behind the camera")
    normal = torso_normal(joints_cam)
    # Look along the normal, into whichever side of the torso the camera sees.
    look = -normal if normal @ corners.mean(axis=0) < 0 else normal
    rotation = Rotation.align_vectors([look], [[0.0, 0.0, 1.0]])[0].as_matrix()
    in_view = corners @ rotation  # R^T p for every corner
    if np.any(in_view[:, 2] <= 1e-6):
        raise TorsoViewError("the torso is seen edge-on: no view along its normal")
    src = pinhole(K, corners)
    dst = pinhole(K, in_view)
    dst += src.mean(axis=0) - dst.mean(axis=0)
    H = cv2.getPerspectiveTransform(src.astype(np.float32), dst.astype(np.float32))
    return TorsoView(H, src, dst, rotation, normal)

"""Torso-normal-aligned views from 2D shoulder and hip keypoints (ControllerPose §4.3).

The paper: "using the resulting shoulder and hip keypoints, we create torso-normal-aligned
views using a four-point perspective transform. From this viewpoint, the lower body is more
proportionally correct". A real system has only the 2D keypoints its detector reported, so
the transform here is built from them alone: the four source points are the detected
shoulders and hips (:data:`TORSO_CORNERS`); the four destination points are a frontal torso
of standard proportions (shoulder width 1, hip width :data:`HIP_TO_SHOULDER_WIDTH`, shoulder
line to hip line :data:`TORSO_HEIGHT_TO_SHOULDER_WIDTH`), upright along the source's hip to
shoulder direction, with the source's centroid, area and handedness (a torso seen from behind
stays seen from behind). The perspective transform maps the image of the torso plane onto its
frontal view exactly when the torso has those proportions; points off that plane move as a
homography of the plane moves them. Keypoints are then detected again in the view
(:mod:`render_cams.fisheye.pose2d`).

Proportions: of the avatar rig's rest pose (``avatar_models/rigs``; shoulder joints 0.453 m
apart, hip joints 0.182 m, 0.504 m from the hip line to the shoulder line).

Vectorised over any leading axes; the 4-point transform is solved as the 8 x 8 linear system
``cv2.getPerspectiveTransform`` solves, for all frames at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.body17 import INDEX

TORSO_CORNERS = ("l_shoulder", "r_shoulder", "r_hip", "l_hip")  # the four points, in order
CORNER_INDICES = np.array([INDEX[n] for n in TORSO_CORNERS])
# The avatar rig's rest torso, metres (module docstring).
REST_SHOULDER_WIDTH_M, REST_HIP_WIDTH_M, REST_TORSO_HEIGHT_M = 0.453, 0.182, 0.504
HIP_TO_SHOULDER_WIDTH = REST_HIP_WIDTH_M / REST_SHOULDER_WIDTH_M
TORSO_HEIGHT_TO_SHOULDER_WIDTH = REST_TORSO_HEIGHT_M / REST_SHOULDER_WIDTH_M
MIN_AREA_PX2 = 16.0  # a smaller torso quad gives no usable view
# The frontal torso in (across, up) coordinates, corners in TORSO_CORNERS order.
FRONTAL = np.array(
    [
        [0.5, 0.5 * TORSO_HEIGHT_TO_SHOULDER_WIDTH],
        [-0.5, 0.5 * TORSO_HEIGHT_TO_SHOULDER_WIDTH],
        [-0.5 * HIP_TO_SHOULDER_WIDTH, -0.5 * TORSO_HEIGHT_TO_SHOULDER_WIDTH],
        [0.5 * HIP_TO_SHOULDER_WIDTH, -0.5 * TORSO_HEIGHT_TO_SHOULDER_WIDTH],
    ]
)


class TorsoViewError(AvatarsimError, ValueError):
    """The torso keypoints give no view (missing, degenerate or not a convex quad)."""


def signed_area(quad: np.ndarray) -> np.ndarray:
    """``(...)`` signed (shoelace) area of quadrilaterals ``(..., 4, 2)``."""
    x, y = quad[..., 0], quad[..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=-1) - np.roll(x, -1, axis=-1) * y, axis=-1)


def convex(quad: np.ndarray) -> np.ndarray:
    """``(...)`` bool: quadrilaterals ``(..., 4, 2)`` that are strictly convex."""
    edges = np.roll(quad, -1, axis=-2) - quad
    nxt = np.roll(edges, -1, axis=-2)
    turn = edges[..., 0] * nxt[..., 1] - edges[..., 1] * nxt[..., 0]
    return np.all(turn > 0, axis=-1) | np.all(turn < 0, axis=-1)


def frontal_corners(src: np.ndarray) -> np.ndarray:
    """``(..., 4, 2)`` destination corners for source corners ``src`` ``(..., 4, 2)``
    (module docstring)."""
    centre = src.mean(axis=-2)
    up = 0.5 * (src[..., 0, :] + src[..., 1, :] - src[..., 2, :] - src[..., 3, :])
    up = up / np.maximum(np.linalg.norm(up, axis=-1, keepdims=True), 1e-12)
    # (across, up) with across = (-up_y, up_x) is a left-handed basis of the image: it flips
    # the frontal torso's handedness; turn ``across`` round where that would mirror ``src``.
    keep = np.sign(signed_area(src)) == -np.sign(signed_area(FRONTAL))
    across = np.stack([-up[..., 1], up[..., 0]], axis=-1) * np.where(keep, 1.0, -1.0)[..., None]
    scale = np.sqrt(np.abs(signed_area(src)) / abs(signed_area(FRONTAL)))
    return centre[..., None, :] + scale[..., None, None] * (
        FRONTAL[:, :1] * across[..., None, :] + FRONTAL[:, 1:] * up[..., None, :]
    )


def perspective_transform(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` homographies (``H[2, 2] = 1``) taking four points ``src`` ``(..., 4, 2)``
    onto ``dst`` ``(..., 4, 2)``: ``cv2.getPerspectiveTransform``'s system, batched."""
    x, y = src[..., 0], src[..., 1]
    u, v = dst[..., 0], dst[..., 1]
    zero, one = np.zeros_like(x), np.ones_like(x)
    rows_u = np.stack([x, y, one, zero, zero, zero, -x * u, -y * u], axis=-1)
    rows_v = np.stack([zero, zero, zero, x, y, one, -x * v, -y * v], axis=-1)
    A = np.concatenate([rows_u, rows_v], axis=-2)  # (..., 8, 8)
    b = np.concatenate([u, v], axis=-1)  # (..., 8)
    h = np.linalg.solve(A, b[..., None])[..., 0]
    return np.concatenate([h, np.ones((*h.shape[:-1], 1))], axis=-1).reshape(*h.shape[:-1], 3, 3)


def apply_homography(H: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """``(..., J, 2)`` pixels ``uv`` ``(..., J, 2)`` moved by homographies ``H`` ``(..., 3, 3)``."""
    p = np.einsum("...ab,...jb->...ja", H[..., :, :2], uv) + H[..., None, :, 2]
    return p[..., :2] / p[..., 2:]


@dataclass(frozen=True)
class TorsoView:
    """Torso-normal-aligned views over leading axes ``(...)``.

    Attributes:
        H: ``(..., 3, 3)`` perspective transforms, source pixels -> view pixels (identity
            where ``valid`` is False).
        src, dst: ``(..., 4, 2)`` the shoulders and hips (``TORSO_CORNERS``) in the source
            image and in the view.
        valid: ``(...)`` bool: the four keypoints gave a view.
    """

    H: np.ndarray
    src: np.ndarray
    dst: np.ndarray
    valid: np.ndarray

    def warp(self, image: np.ndarray) -> np.ndarray:
        """The view of one ``image`` ``(h, w[, c])`` (a single view: ``H`` ``(3, 3)``) by
        ``cv2.warpPerspective``, same size."""
        if not bool(self.valid):
            raise TorsoViewError("no torso view: the shoulders and hips do not give one")
        return cv2.warpPerspective(image, self.H, (image.shape[1], image.shape[0]))


def torso_view(keypoints: np.ndarray, detected: np.ndarray | None = None) -> TorsoView:
    """The torso-normal-aligned views of body17 2D keypoints ``keypoints`` ``(..., 17, 2)``
    of which ``detected`` ``(..., 17)`` bool (default all) were reported: valid where both
    shoulders and both hips were, form a convex quad of at least :data:`MIN_AREA_PX2`."""
    src = np.asarray(keypoints, float)[..., CORNER_INDICES, :]
    found = np.ones(src.shape[:-1], bool) if detected is None else detected[..., CORNER_INDICES]
    ok = np.all(found, axis=-1) & np.all(np.isfinite(src), axis=(-2, -1))
    safe = np.where(ok[..., None, None], src, FRONTAL)
    ok &= convex(safe) & (np.abs(signed_area(safe)) >= MIN_AREA_PX2)
    safe = np.where(ok[..., None, None], safe, FRONTAL)
    dst = frontal_corners(safe)
    H = np.where(ok[..., None, None], perspective_transform(safe, dst), np.eye(3))
    return TorsoView(H, src, np.where(ok[..., None, None], dst, np.nan), ok)

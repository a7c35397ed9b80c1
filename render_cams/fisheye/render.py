"""Geometrically exact fisheye rendering: cube-map faces resampled through the fisheye rays.

A rasteriser only draws pinhole images, so :class:`FisheyeRenderer` renders the cube faces
(camera-frame +z, +-x, +-y; the -z face is never needed inside the 90 deg image circle) that
the image's rays hit, as 90 deg pinhole views from the fisheye's centre, and looks up every
fisheye pixel's ray (from ``cv2.fisheye.undistortPoints``) in them with one ``cv2.remap``.
The maps are computed once per camera model. Each face is rendered a little wider than
90 deg so that bilinear lookups never straddle two faces.

Depth: the fisheye depth image holds the **range** along each pixel's ray (metres, 0 where
nothing was hit, also outside the image circle), which is what keypoint visibility needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from render_cams.fisheye.model import FisheyeModel
from render_cams.scene import BodyScene

# Face camera axes (columns x, y, z) in the fisheye camera frame, OpenCV convention.
_FACES: dict[str, np.ndarray] = {
    "front": np.eye(3),
    "left": np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float).T,  # looks along -x
    "right": np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0]], float).T,  # looks along +x
    "up": np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float).T,  # looks along -y
    "down": np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float).T,  # looks along +y
}
FACE_MARGIN_PX = 2  # pixels of each face beyond the 90 deg cube edge


@dataclass(frozen=True)
class CubeMaps:
    """Precomputed lookup of a fisheye image in an atlas of cube faces side by side.

    Attributes:
        faces: names of the faces rendered, in atlas order.
        rotations: ``(F, 3, 3)`` face camera axes in the fisheye frame.
        face_K: ``(3, 3)`` pinhole K of every face.
        face_size: face width = height in pixels.
        map_x, map_y: ``(H, W)`` float32 atlas coordinates of every fisheye pixel.
        range_scale: ``(H, W)`` float32 face-z-depth -> range along the ray factor (0 outside).
    """

    faces: tuple[str, ...]
    rotations: np.ndarray
    face_K: np.ndarray
    face_size: int
    map_x: np.ndarray
    map_y: np.ndarray
    range_scale: np.ndarray


def cube_maps(model: FisheyeModel, face_size: int | None = None) -> CubeMaps:
    """The lookup of ``model``'s pixels in cube faces of ``face_size`` pixels (default: the
    fisheye's resolution at its centre, ``2 max(fx, fy)``, so no detail is lost there)."""
    rays, inside = model.rays()
    if face_size is None:
        face_size = int(np.ceil(2.0 * max(model.K[0, 0], model.K[1, 1]) / 8.0) * 8)
    size = int(face_size)
    # Tangents in [-1, 1] span size - 1 - 2 * margin pixels between the edge pixel centres.
    f = 0.5 * (size - 1) - FACE_MARGIN_PX
    c = 0.5 * (size - 1)
    face_K = np.array([[f, 0.0, c], [0.0, f, c], [0.0, 0.0, 1.0]])
    names = list(_FACES)
    rotations = np.stack([_FACES[n] for n in names])
    # A ray belongs to the face whose axis it is closest to.
    along = np.einsum("fk,hwk->hwf", rotations[:, :, 2], np.nan_to_num(rays))
    face = np.argmax(along, axis=-1)
    used = [k for k in range(len(names)) if np.any(inside & (face == k))]
    slot = np.full(len(names), -1)
    slot[used] = np.arange(len(used))
    local = np.einsum("hwji,hwj->hwi", rotations[face], np.nan_to_num(rays))  # R^T @ ray
    z = np.where(inside, local[..., 2], 1.0)
    map_x = f * local[..., 0] / z + c + size * slot[face]
    map_y = f * local[..., 1] / z + c
    map_x[~inside] = map_y[~inside] = -1e4  # far outside the atlas: border value (0)
    return CubeMaps(
        faces=tuple(names[k] for k in used),
        rotations=rotations[used],
        face_K=face_K,
        face_size=size,
        map_x=map_x.astype(np.float32),
        map_y=map_y.astype(np.float32),
        range_scale=np.where(inside, 1.0 / z, 0.0).astype(np.float32),
    )


class FisheyeRenderer:
    """Renders a :class:`BodyScene` through one fisheye model.

    Args:
        scene: the scene (posed by the caller with ``scene.update``).
        model: the fisheye camera.
        face_size: cube face size in pixels (default from :func:`cube_maps`).
    """

    def __init__(self, scene: BodyScene, model: FisheyeModel, face_size: int | None = None):
        self.scene = scene
        self.model = model
        self.maps = cube_maps(model, face_size)
        n, size = len(self.maps.faces), self.maps.face_size
        self._color_atlas = np.zeros((size, n * size, 3), np.uint8)
        self._depth_atlas = np.zeros((size, n * size), np.float32)

    def render(self, camera_to_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Colour ``(H, W, 3)`` uint8 and range ``(H, W)`` float32 metres of the fisheye at
        ``camera_to_world`` (4x4, OpenCV axes)."""
        pose = np.asarray(camera_to_world, float)
        size, maps = self.maps.face_size, self.maps
        for k, rotation in enumerate(maps.rotations):
            face_pose = pose.copy()
            face_pose[:3, :3] = pose[:3, :3] @ rotation
            color, depth = self.scene.render(face_pose, maps.face_K, size, size)
            self._color_atlas[:, k * size : (k + 1) * size] = color
            self._depth_atlas[:, k * size : (k + 1) * size] = depth
        color = cv2.remap(self._color_atlas, maps.map_x, maps.map_y, cv2.INTER_LINEAR)
        # Nearest for depth: interpolating across a silhouette edge invents surfaces.
        depth = cv2.remap(self._depth_atlas, maps.map_x, maps.map_y, cv2.INTER_NEAREST)
        return color, depth * maps.range_scale

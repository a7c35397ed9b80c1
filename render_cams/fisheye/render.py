"""Geometrically exact fisheye rendering: cube-map faces resampled through the fisheye rays.

A rasteriser only draws pinhole images, so :class:`FisheyeRenderer` renders the cube faces
(camera-frame +z, +-x, +-y; the -z face is never needed inside the 90 deg image circle) that
the image's rays hit, as pinhole views from the fisheye's centre, and looks up every fisheye
pixel's ray (from :meth:`FisheyeModel.rays`, OpenCV's model) in them with one ``cv2.remap``.
The maps are computed once per camera model.

By default each face is cropped to the part of it that the fisheye's rays hit (a narrow strip
for the side faces of a 150 x 120 deg lens) and rendered at the focal length that matches the
fisheye's resolution there: at least one face pixel per fisheye pixel in every direction (the
smallest singular value of the fisheye-pixel -> face-pixel Jacobian is >= 1), so no detail
the fisheye resolves is lost, and not much more. ``face_size`` renders full 90 deg faces of
that size instead. Faces are rendered a few pixels beyond the used part so that bilinear
lookups never leave them.

Depth: the fisheye depth image holds the **range** along each pixel's ray (metres, 0 where
nothing was hit, also outside the image circle), which is what keypoint visibility needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.scene import BodyScene

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
    """Precomputed lookup of a fisheye image in an atlas of pinhole faces side by side.

    Attributes:
        faces: names of the faces rendered, in atlas order.
        rotations: ``(F, 3, 3)`` face camera axes in the fisheye frame.
        face_K: ``(F, 3, 3)`` pinhole K of every face (crop offset in the principal point).
        face_sizes: ``(F, 2)`` int width, height of every face in pixels.
        map_x, map_y: ``(H, W)`` float32 atlas coordinates of every fisheye pixel.
        range_scale: ``(H, W)`` float32 face-z-depth -> range along the ray factor (0 outside).
    """

    faces: tuple[str, ...]
    rotations: np.ndarray
    face_K: np.ndarray
    face_sizes: np.ndarray
    map_x: np.ndarray
    map_y: np.ndarray
    range_scale: np.ndarray

    @property
    def atlas_shape(self) -> tuple[int, int]:
        """Height and width of the atlas the faces are laid out in."""
        return int(self.face_sizes[:, 1].max()), int(self.face_sizes[:, 0].sum())

    @property
    def face_offsets(self) -> np.ndarray:
        """``(F,)`` atlas column of every face's first pixel."""
        return np.concatenate([[0], np.cumsum(self.face_sizes[:, 0])[:-1]])


def _matched_focal(tangent: np.ndarray, mask: np.ndarray) -> float:
    """Smallest pinhole focal length giving >= 1 face pixel per fisheye pixel on ``mask``.

    ``tangent`` ``(H, W, 2)`` holds every fisheye pixel's face-plane coordinates ``(x/z, y/z)``
    (smooth over ``mask`` and its neighbours). Face pixels are ``f * tangent``, so the
    fisheye -> face Jacobian is ``f J`` with ``J = d tangent / d (u, v)``; its smallest
    singular value is ``f sigma_min(J)``, which must be >= 1 everywhere on the face.
    """
    da_dv, da_du = np.gradient(tangent[..., 0])
    db_dv, db_du = np.gradient(tangent[..., 1])
    J = np.stack([[da_du, da_dv], [db_du, db_dv]])[..., mask]  # (2, 2, N)
    trace = np.einsum("ijn,ijn->n", J, J)
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    sigma_min_sq = 0.5 * (trace - np.sqrt(np.maximum(trace**2 - 4.0 * det**2, 0.0)))
    return float(1.0 / np.sqrt(sigma_min_sq.min()))


def cube_maps(model: FisheyeModel, face_size: int | None = None) -> CubeMaps:
    """The lookup of ``model``'s pixels in cube faces: cropped and resolution-matched by
    default, or full 90 deg faces of ``face_size`` pixels."""
    rays, inside = model.rays()
    rays = np.nan_to_num(rays)
    names = list(_FACES)
    rotations = np.stack([_FACES[n] for n in names])
    # A ray belongs to the face whose axis it is closest to.
    face = np.argmax(np.einsum("fk,hwk->hwf", rotations[:, :, 2], rays), axis=-1)
    used = [k for k in range(len(names)) if np.any(inside & (face == k))]
    interior = cv2.erode(inside.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    map_x = np.full(inside.shape, -1e4)  # far outside the atlas: border value (0)
    map_y = np.full(inside.shape, -1e4)
    range_scale = np.zeros(inside.shape)
    face_K, face_sizes, offset = [], [], 0
    for k in used:
        mine = inside & (face == k)
        local = rays @ rotations[k]  # R^T @ ray, (H, W, 3)
        z = np.where(local[..., 2] > 1e-6, local[..., 2], 1e-6)
        tangent = local[..., :2] / z[..., None]
        if face_size is None:
            # Differences across the image circle's rim are meaningless: judge within it.
            f = _matched_focal(tangent, mine & interior)
            low = tangent[mine].min(axis=0) * f - FACE_MARGIN_PX
            size = np.ceil(tangent[mine].max(axis=0) * f + FACE_MARGIN_PX - low).astype(int) + 1
            centre = -low
        else:
            # Tangents in [-1, 1] span size - 1 - 2 * margin pixels between edge pixel centres.
            f = 0.5 * (face_size - 1) - FACE_MARGIN_PX
            size = np.array([face_size, face_size])
            centre = np.full(2, 0.5 * (face_size - 1))
        face_K.append([[f, 0.0, centre[0]], [0.0, f, centre[1]], [0.0, 0.0, 1.0]])
        face_sizes.append(size)
        map_x[mine] = f * tangent[mine, 0] + centre[0] + offset
        map_y[mine] = f * tangent[mine, 1] + centre[1]
        range_scale[mine] = 1.0 / z[mine]
        offset += size[0]
    return CubeMaps(
        faces=tuple(names[k] for k in used),
        rotations=rotations[used],
        face_K=np.array(face_K),
        face_sizes=np.array(face_sizes),
        map_x=map_x.astype(np.float32),
        map_y=map_y.astype(np.float32),
        range_scale=range_scale.astype(np.float32),
    )


class FisheyeRenderer:
    """Renders a :class:`BodyScene` through one fisheye model.

    Args:
        scene: the scene (posed by the caller with ``scene.update``).
        model: the fisheye camera.
        face_size: full cube faces of this many pixels instead of cropped, resolution-matched
            ones (see :func:`cube_maps`).
    """

    def __init__(self, scene: BodyScene, model: FisheyeModel, face_size: int | None = None):
        self.scene = scene
        self.model = model
        self.maps = cube_maps(model, face_size)
        self._color_atlas = np.zeros((*self.maps.atlas_shape, 3), np.uint8)
        self._depth_atlas = np.zeros(self.maps.atlas_shape, np.float32)
        # Fixed-point maps (1/32 px) remap several times faster than float ones.
        self._linear_maps = cv2.convertMaps(self.maps.map_x, self.maps.map_y, cv2.CV_16SC2)
        self._nearest_map, _ = cv2.convertMaps(
            self.maps.map_x, self.maps.map_y, cv2.CV_16SC2, nninterpolation=True
        )

    def render(self, camera_to_world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Colour ``(H, W, 3)`` uint8 and range ``(H, W)`` float32 metres of the fisheye at
        ``camera_to_world`` (4x4, OpenCV axes)."""
        pose = np.asarray(camera_to_world, float)
        maps = self.maps
        for rotation, K, (w, h), x0 in zip(
            maps.rotations, maps.face_K, maps.face_sizes, maps.face_offsets, strict=True
        ):
            face_pose = pose.copy()
            face_pose[:3, :3] = pose[:3, :3] @ rotation
            color, depth = self.scene.render(face_pose, K, w, h)
            self._color_atlas[:h, x0 : x0 + w] = color
            self._depth_atlas[:h, x0 : x0 + w] = depth
        color = cv2.remap(self._color_atlas, *self._linear_maps, cv2.INTER_LINEAR)
        # Nearest for depth: interpolating across a silhouette edge invents surfaces.
        depth = cv2.remap(self._depth_atlas, self._nearest_map, None, cv2.INTER_NEAREST)
        return color, depth * maps.range_scale

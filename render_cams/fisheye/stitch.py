"""Undistortion, cylindrical projection and stitching of a controller's two cameras
(ControllerPose §4.2, Figure 4D-F).

The paper corrects each fisheye, projects it onto a cylinder and stitches the two images
"into a panorama with a gradient blend", from stitch parameters calibrated once because the
geometry between the cameras is fixed. Here that one-time calibration is computed from the
known relative pose of the two cameras (:mod:`render_cams.fisheye.rig`) and the lens model,
as exact lookup maps: :func:`stitch_params` once, :func:`stitch` per frame (two
``cv2.remap`` calls and a weighted sum).

The cylinder. The two cameras of a controller differ by a pitch about their shared image x
axis, so the panorama grows along the image's vertical, to 185 deg (§4.1): its cylinder's
axis is that shared x axis, rows are the angle about it (linear, so more than 180 deg fit)
and columns the height along it. This is the usual horizontal panorama turned by 90 deg; as
there world lines parallel to the cylinder axis stay straight image lines (here rows) and
lines in the central plane stay on the centre column. The undistortion to a pinhole image
(§4.2's "correct each camera for fisheye distortion") is :func:`undistortion_maps`; the
cylinder maps go straight from the fisheye, which avoids a pinhole image of a 150 deg lens.

Width: the paper's composite is "roughly 185 deg vertical by 150 deg horizontal" (§4.2): the
columns span the lenses' full 150 deg horizontal field of view. Along the cylinder's axis
columns grow as ``tan`` of the angle, so the composite is wide (about 1711 x 741 pixels at the
paper's 640 x 480): :meth:`StitchParams.coverage` measures what it spans.

Filtering: frames the image filter dropped (:mod:`render_cams.fisheye.bad_frames`, §4.2
"unusable frames ... that we filter") do not enter the blend: ``stitch(images, usable)``
renormalises the weights over the usable cameras, so a dropped frame leaves its camera's
part of the composite black rather than corrupting it.

Parallax: the cameras are 14 cm apart, so one set of maps can only join points at one
distance exactly. The cylinder has a radius of ``STITCH_DISTANCE_M`` around the midpoint of
the camera centres: points on that surface land on the same composite pixel from both
cameras; the default is ControllerPose §3's mean camera-to-body distance, 43 cm.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.rig import ControllerCamera

STITCH_DISTANCE_M = 0.43  # ControllerPose §3: mean camera-to-body distance
MAX_HALF_WIDTH_DEG = 75.0  # half of the composite's 150 deg horizontal field of view (§4.2)


def undistortion_maps(
    model: FisheyeModel, K_new: np.ndarray, size: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """``(H, W)`` float32 x and y fisheye coordinates of every pixel of a pinhole image with
    camera matrix ``K_new`` ``(3, 3)`` and ``size`` ``(W, H)``, from
    ``cv2.fisheye.initUndistortRectifyMap`` (no rectifying rotation); apply with
    ``cv2.remap``."""
    return cv2.fisheye.initUndistortRectifyMap(
        model.K, model.D, np.eye(3), np.asarray(K_new, float), tuple(size), cv2.CV_32FC1
    )


@dataclass(frozen=True)
class Cylinder:
    """A cylindrical image: pixel ``(u, v)`` sees the direction at angle
    ``phi = (v - cv) / focal_px`` about the cylinder's x axis (towards +y, image down) and at
    height ``a = (u - cu) / focal_px`` along it per unit distance from the axis.

    Attributes:
        pose: ``(4, 4)`` cylinder frame in the controller frame (x: axis, z: phi = 0).
        radius_m: radius of the stitch surface.
        focal_px: pixels per radian of ``phi`` (and per unit of ``a``).
        cu, cv: pixel of ``phi = 0, a = 0``; width, height: image size.
    """

    pose: np.ndarray
    radius_m: float
    focal_px: float
    cu: float
    cv: float
    width: int
    height: int

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixels ``(..., 2)`` of points ``(..., 3)`` in the cylinder frame, as seen from
        its axis."""
        p = np.asarray(points, float)
        across = np.hypot(p[..., 1], p[..., 2])
        phi = np.arctan2(p[..., 1], p[..., 2])
        return np.stack(
            [self.cu + self.focal_px * p[..., 0] / across, self.cv + self.focal_px * phi], -1
        )

    def surface(self, uv: np.ndarray) -> np.ndarray:
        """``(..., 3)`` points of the stitch surface (cylinder frame) seen at pixels ``uv``
        ``(..., 2)``."""
        uv = np.asarray(uv, float)
        a = (uv[..., 0] - self.cu) / self.focal_px
        phi = (uv[..., 1] - self.cv) / self.focal_px
        return self.radius_m * np.stack([a, np.sin(phi), np.cos(phi)], axis=-1)

    def hit(self, origin: np.ndarray, rays: np.ndarray) -> np.ndarray:
        """``(..., 3)`` where rays ``(..., 3)`` from ``origin`` ``(3,)`` (inside the cylinder,
        cylinder frame) leave the stitch surface."""
        a = rays[..., 1] ** 2 + rays[..., 2] ** 2
        b = origin[1] * rays[..., 1] + origin[2] * rays[..., 2]
        c = origin[1] ** 2 + origin[2] ** 2 - self.radius_m**2
        with np.errstate(invalid="ignore", divide="ignore"):
            reach = (-b + np.sqrt(b * b - a * c)) / a
        return origin + reach[..., None] * rays


def camera_pose(camera: ControllerCamera) -> np.ndarray:
    """``(4, 4)`` camera-to-controller pose (OpenCV camera axes)."""
    pose = np.eye(4)
    pose[:3, :3] = camera.axes
    pose[:3, 3] = camera.position
    return pose


def stitch_cylinder(
    model: FisheyeModel,
    cameras: Sequence[ControllerCamera],
    radius_m: float = STITCH_DISTANCE_M,
    max_half_width_deg: float = MAX_HALF_WIDTH_DEG,
) -> Cylinder:
    """The cylinder that holds both cameras' views: axis along their mean x axis, centred
    between them, ``phi = 0`` on the bisector of their optical axes, rows spanning both
    vertical fields of view at the fisheye's central resolution (``fy`` px per radian)."""
    axes = np.stack([c.axes for c in cameras])
    x = axes[:, :, 0].mean(axis=0)
    x /= np.linalg.norm(x)
    z = axes[:, :, 2].mean(axis=0)
    z -= (z @ x) * x
    z /= np.linalg.norm(z)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = np.mean([c.position for c in cameras], axis=0)
    optical = np.einsum("ba,cb->ca", pose[:3, :3], axes[:, :, 2])  # (C, 3) in the cylinder
    phi = np.arctan2(optical[:, 1], optical[:, 2])
    fov_x, fov_y = model.fov_rad
    phi_lo, phi_hi = phi.min() - 0.5 * fov_y, phi.max() + 0.5 * fov_y
    focal = float(model.K[1, 1])
    half_width = focal * np.tan(min(0.5 * fov_x, np.radians(max_half_width_deg)))
    width = 2 * int(np.ceil(half_width)) + 1
    return Cylinder(
        pose,
        float(radius_m),
        focal,
        0.5 * (width - 1),
        -focal * phi_lo,
        width,
        int(np.ceil(focal * (phi_hi - phi_lo))) + 1,
    )


@dataclass(frozen=True)
class StitchParams:
    """One-time stitch parameters of a camera pair (ControllerPose §4.2).

    Attributes:
        model: the lens of both cameras.
        cylinder: the composite's projection.
        camera_in_cylinder: ``(C, 4, 4)`` camera poses in the cylinder frame.
        map_x, map_y: ``(C, H, W)`` float32 camera pixel seen at each composite pixel.
        valid: ``(C, H, W)`` bool: the camera sees that composite pixel.
        weights: ``(C, H, W)`` float32 gradient-blend weights: sum 1 where any camera sees,
            ramping linearly along each column across the overlap, 0 where none does.
    """

    model: FisheyeModel
    cylinder: Cylinder
    camera_in_cylinder: np.ndarray
    map_x: np.ndarray
    map_y: np.ndarray
    valid: np.ndarray
    weights: np.ndarray

    def to_composite(self, camera: int, uv: np.ndarray) -> np.ndarray:
        """Composite pixels ``(..., 2)`` of ``camera``'s pixels ``uv`` ``(..., 2)`` (e.g. 2D
        keypoints): their rays meet the stitch surface there."""
        pose = self.camera_in_cylinder[camera]
        rays = self.model.unproject(uv) @ pose[:3, :3].T
        return self.cylinder.project(self.cylinder.hit(pose[:3, 3], rays))

    def warp(self, images: Sequence[np.ndarray]) -> np.ndarray:
        """``(C, H, W[, 3])`` each camera image ``(h, w[, 3])`` resampled onto the cylinder
        (unweighted; edge pixels replicated where the camera sees nothing, weight 0 there)."""
        return np.stack(
            [
                cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
                for img, mx, my in zip(images, self.map_x, self.map_y, strict=True)
            ]
        )

    def stitch(self, images: Sequence[np.ndarray], usable: np.ndarray | None = None) -> np.ndarray:
        """``(H, W[, 3])`` the gradient-blended composite of the camera images, in their
        dtype; only the cameras ``usable`` ``(C,)`` bool (default all) contribute, with the
        blend weights renormalised over them (0 where none of them sees)."""
        warped = self.warp(images).astype(np.float32)
        weights = self.blend_weights(usable)
        w = weights if warped.ndim == 3 else weights[..., None]
        out = np.sum(w * warped, axis=0)
        if np.issubdtype(images[0].dtype, np.integer):
            out = np.clip(np.round(out), 0, np.iinfo(images[0].dtype).max)
        return out.astype(images[0].dtype)

    def blend_weights(self, usable: np.ndarray | None = None) -> np.ndarray:
        """``(C, H, W)`` float32 blend weights of the ``usable`` ``(C,)`` cameras (default
        all): sum 1 where one of them sees, 0 elsewhere."""
        if usable is None:
            return self.weights
        mask = np.asarray(usable, bool)[:, None, None]
        kept = np.where(mask & self.valid, np.maximum(self.weights, 1e-6), 0.0)
        total = kept.sum(axis=0)
        return np.where(total > 0, kept / np.maximum(total, 1e-12), 0.0).astype(np.float32)

    def coverage(self) -> dict[str, float]:
        """What the composite spans: ``vertical_deg`` (angle about the axis, down the centre
        column) and ``horizontal_deg`` (angle along the axis, over all rows), both between the
        outermost pixels a camera sees, ``seen_fraction`` of all composite pixels, and the
        composite's ``width`` and ``height``."""
        cyl = self.cylinder
        seen = self.valid.any(axis=0)
        rows = np.flatnonzero(seen[:, int(round(cyl.cu))])
        cols = np.flatnonzero(seen.any(axis=0))
        along = np.arctan((cols[[0, -1]] - cyl.cu) / cyl.focal_px)
        return {
            "vertical_deg": float(np.degrees((rows[-1] - rows[0] + 1) / cyl.focal_px)),
            "horizontal_deg": float(np.degrees(along[1] - along[0])),
            "seen_fraction": float(seen.mean()),
            "width": cyl.width,
            "height": cyl.height,
        }


def column_ramp(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """``(H, W)`` weight of the upper camera: 1 where only ``first`` ``(H, W)`` sees, 0 where
    only ``second`` does, falling linearly from 1 to 0 down each column's overlap."""
    both = first & second
    rows = np.arange(both.shape[0], dtype=np.float64)[:, None]
    top = np.argmax(both, axis=0)
    bottom = both.shape[0] - 1 - np.argmax(both[::-1], axis=0)
    ramp = np.clip((bottom - rows) / np.maximum(bottom - top, 1), 0.0, 1.0)
    return np.where(both, ramp, first.astype(np.float64))


def stitch_params(
    model: FisheyeModel,
    cameras: Sequence[ControllerCamera],
    radius_m: float = STITCH_DISTANCE_M,
    max_half_width_deg: float = MAX_HALF_WIDTH_DEG,
) -> StitchParams:
    """The one-time stitch parameters of a controller's two ``cameras`` (the ring and grip
    cameras of :func:`~render_cams.fisheye.rig.controller_cameras`) with lens ``model``.

    Computed once per lens, mount and cylinder in a process (seconds at 640 x 480: a
    projection of every composite pixel into both cameras) and shared after: treat the
    arrays as read-only."""
    if len(cameras) != 2:
        raise ValueError(f"stitching joins two cameras, got {len(cameras)}")
    key = (
        model.K.tobytes(),
        model.D.tobytes(),
        model.width,
        model.height,
        tuple((c.position.tobytes(), c.axes.tobytes()) for c in cameras),
        float(radius_m),
        float(max_half_width_deg),
    )
    if key not in _STITCH_CACHE:
        if len(_STITCH_CACHE) >= STITCH_CACHE_SIZE:
            _STITCH_CACHE.pop(next(iter(_STITCH_CACHE)))  # the oldest
        _STITCH_CACHE[key] = compute_stitch_params(model, cameras, radius_m, max_half_width_deg)
    return _STITCH_CACHE[key]


STITCH_CACHE_SIZE = 4  # both controllers of two lenses; about 35 MB each at 640 x 480
_STITCH_CACHE: dict[tuple, StitchParams] = {}


def compute_stitch_params(
    model: FisheyeModel,
    cameras: Sequence[ControllerCamera],
    radius_m: float,
    max_half_width_deg: float,
) -> StitchParams:
    """:func:`stitch_params` without the cache."""
    cylinder = stitch_cylinder(model, cameras, radius_m, max_half_width_deg)
    to_cylinder = np.linalg.inv(cylinder.pose)
    poses = np.stack([to_cylinder @ camera_pose(c) for c in cameras])
    v, u = np.mgrid[0 : cylinder.height, 0 : cylinder.width].astype(np.float64)
    surface = cylinder.surface(np.stack([u, v], axis=-1))
    # Surface points in each camera frame: R^T (p - t).
    in_camera = (surface - poses[:, None, None, :3, 3]) @ poses[:, None, :3, :3]
    uv, valid = model.project(in_camera)
    uv = np.where(valid[..., None], uv, -1.0).astype(np.float32)
    # The camera whose optical axis points further up (-y) takes the top of the overlap.
    upper = int(np.argmin(poses[:, 1, 2]))
    first = column_ramp(valid[upper], valid[1 - upper])
    weights = np.empty(valid.shape, np.float32)
    weights[upper] = first
    weights[1 - upper] = np.where(valid.any(axis=0), 1.0 - first, 0.0)
    return StitchParams(
        model, cylinder, poses, uv[..., 0].copy(), uv[..., 1].copy(), valid, weights
    )

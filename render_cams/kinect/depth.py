"""Kinect depth frames and body-index maps rendered from a :class:`BodyScene`.

A frame is what the SDKs hand out: depth as ``uint16`` millimetres (0 = no reading) and a
body-index map as ``uint8`` (0 for the tracked body, 255 for no body, as Kinect V2's
``BodyIndexFrame`` and Azure's ``k4abt`` body-index map). Both come from one segmentation
pass of the scene (depth and part labels, agreeing at every pixel), then the depth noise
model; lateral noise moves the body index with the depth so the two stay aligned.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from avatarsim.render_cams.kinect.noise import DepthNoiseModel
from avatarsim.render_cams.kinect.parts import part_image
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError, get_sensor
from avatarsim.render_cams.scene import BodyScene

BODY_INDEX_NONE = 255
"""Body-index value of pixels without a body (Kinect V2 and Azure Kinect SDKs)."""


@dataclass(frozen=True)
class DepthFrame:
    """One Kinect frame: ``depth_mm (H, W)`` uint16, ``body_index (H, W)`` uint8 and the
    ground-truth body-part labels ``parts (H, W)`` uint8 (:mod:`.parts`; 0 where there is no
    body or no depth reading), aligned pixel for pixel with the depth."""

    depth_mm: np.ndarray
    body_index: np.ndarray
    parts: np.ndarray

    @property
    def depth_m(self) -> np.ndarray:
        """``(H, W)`` float depth in metres (0 = invalid)."""
        return self.depth_mm.astype(float) * 1e-3


class KinectDepthCamera:
    """A Kinect depth camera at a fixed pose.

    Args:
        device: sensor name or :class:`DepthSensor`.
        camera_to_world: ``(4, 4)`` pose, OpenCV axes (see :mod:`render_cams.scene`).
        noise: ``"default"`` (the sensor's model), a :class:`DepthNoiseModel`, or ``None`` for
            clean depth (still invalid out of range and quantised to mm).
    """

    def __init__(
        self,
        device: str | DepthSensor,
        camera_to_world: np.ndarray,
        noise: DepthNoiseModel | None | str = "default",
    ):
        self.sensor = get_sensor(device)
        self.camera_to_world = np.asarray(camera_to_world, float)
        if isinstance(noise, str):
            if noise != "default":
                raise KinectError(f"noise must be 'default', a DepthNoiseModel or None: {noise!r}")
            noise = self.sensor.noise
        self.noise = noise

    def render_clean(self, scene: BodyScene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Noise-free ``(H, W)`` float32 depth in metres (0 = no hit, no range limit),
        ``(H, W)`` int32 segment labels (0 background, > 0 body) and ``(H, W)`` uint8 body
        parts (:func:`~render_cams.kinect.parts.part_image`) of the scene as posed now."""
        s = self.sensor
        pose = self.camera_to_world
        depth, segments = scene.render_depth_and_parts(pose, s.K, s.width, s.height)
        return depth, segments, part_image(scene, depth, segments, s.K, pose)

    def capture(self, scene: BodyScene, rng: np.random.Generator) -> DepthFrame:
        """The depth frame, body-index map and part labels the sensor records of ``scene`` as
        posed now."""
        depth, segments, labelled = self.render_clean(scene)
        near, far = self.sensor.range_m
        if self.noise is None:
            measured = np.where((depth >= near) & (depth <= far), depth, np.float32(0.0))
            body, parts = segments > 0, labelled
        else:
            measured, source = self.noise.apply(depth, self.sensor.K, (near, far), rng)
            body = segments.ravel()[source] > 0
            parts = labelled.ravel()[source].reshape(labelled.shape)
        valid = body & (measured > 0)
        body_index = np.full(measured.shape, BODY_INDEX_NONE, np.uint8)
        body_index[valid] = 0
        parts = np.where(valid, parts, np.uint8(0))
        measured *= 1e3  # to millimetres, rounded half up (depth is never negative)
        measured += 0.5
        return DepthFrame(measured.astype(np.uint16), body_index, parts)


def write_png(image: np.ndarray, path: str | Path) -> Path:
    """Write a ``uint16`` depth (mm) or ``uint8`` map as a lossless PNG, as Kinect tools do."""
    path = Path(path)
    if image.dtype not in (np.uint8, np.uint16) or image.ndim != 2:
        raise KinectError(f"PNG maps must be 2-D uint8/uint16, got {image.dtype} {image.shape}")
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), image):
        raise KinectError(f"could not write {path}")
    return path


def read_depth_png(path: str | Path) -> np.ndarray:
    """``(H, W)`` uint16 millimetres from a depth PNG written by :func:`write_png`."""
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None or image.dtype != np.uint16:
        raise KinectError(f"{path}: not a 16-bit depth PNG")
    return image


def colourise(depth_mm: np.ndarray, range_m: tuple[float, float]) -> np.ndarray:
    """``(H, W, 3)`` uint8 BGR preview of a depth map: near warm, far cool, invalid black."""
    near, far = (r * 1e3 for r in range_m)
    scaled = np.clip((depth_mm.astype(float) - near) / (far - near), 0.0, 1.0)
    colour = cv2.applyColorMap((255 * (1.0 - scaled)).astype(np.uint8), cv2.COLORMAP_TURBO)
    colour[depth_mm == 0] = 0
    return colour

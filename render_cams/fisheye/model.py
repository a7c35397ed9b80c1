"""The OpenCV fisheye (Kannala–Brandt) camera model with validated intrinsics.

A camera-frame point ``(x, y, z)`` (OpenCV axes: x right, y down, z forward) at angle
``theta = atan2(sqrt(x^2 + y^2), z)`` from the optical axis lands at

    theta_d = theta * (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
    u = fx * theta_d * x / r + cx,     v = fy * theta_d * y / r + cy,     r = sqrt(x^2 + y^2)

(OpenCV's ``cv2.fisheye`` documentation; Kannala & Brandt 2006). OpenCV's own functions are
only defined in front of the camera (``z > 0``), so the model's image circle is limited to
``theta < 90 deg``: pixels beyond it (the corners of a very wide lens) see nothing, as the
black corners of a real fisheye. :meth:`FisheyeModel.project` calls
``cv2.fisheye.projectPoints`` once on all points.

Default camera: ControllerPose §4.1, 640x480 with a 150 deg horizontal and 120 deg vertical
field of view (through the principal point, along the image axes).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from avatarsim.avatar_models import AvatarsimError

MODEL_NAME = "opencv_fisheye"
PAPER_SIZE = (640, 480)  # ControllerPose §4.1
PAPER_FOV_DEG = (150.0, 120.0)  # horizontal, vertical; ControllerPose §4.1
HALF_PI = 0.5 * np.pi


class IntrinsicsError(AvatarsimError, ValueError):
    """Impossible fisheye intrinsics (negative focal length, FOV > 180 deg, bad D shape...)."""


def distort_angle(theta: np.ndarray, D: np.ndarray) -> np.ndarray:
    """``theta_d`` of incidence angles ``theta`` (any shape) under coefficients ``D`` (4,)."""
    t2 = theta * theta
    return theta * (1.0 + t2 * (D[0] + t2 * (D[1] + t2 * (D[2] + t2 * D[3]))))


@dataclass(frozen=True, eq=False)
class FisheyeModel:
    """A Kannala–Brandt fisheye camera in OpenCV conventions.

    Attributes:
        K: ``(3, 3)`` camera matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`` (no skew).
        D: ``(4,)`` distortion ``k1..k4``.
        width, height: image size in pixels.
    """

    K: np.ndarray
    D: np.ndarray
    width: int = PAPER_SIZE[0]
    height: int = PAPER_SIZE[1]
    name: str = MODEL_NAME

    def __post_init__(self) -> None:
        K = np.asarray(self.K, dtype=float)
        D = np.asarray(self.D, dtype=float)
        if K.shape != (3, 3) or not np.all(np.isfinite(K)):
            raise IntrinsicsError(f"K must be a finite 3x3 matrix, got shape {K.shape}")
        if D.shape not in ((4,), (4, 1), (1, 4)) or not np.all(np.isfinite(D)):
            raise IntrinsicsError(f"D must hold 4 finite coefficients k1..k4, got shape {D.shape}")
        if not (K[0, 0] > 0 and K[1, 1] > 0):
            raise IntrinsicsError(f"focal lengths must be positive, got {K[0, 0]}, {K[1, 1]}")
        if K[0, 1] != 0 or not np.allclose(K[2], [0.0, 0.0, 1.0]):
            raise IntrinsicsError("K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)")
        if int(self.width) < 2 or int(self.height) < 2:
            raise IntrinsicsError(
                f"image size must be at least 2x2, got {self.width}x{self.height}"
            )
        if not (0 <= K[0, 2] <= self.width - 1 and 0 <= K[1, 2] <= self.height - 1):
            raise IntrinsicsError(f"principal point ({K[0, 2]}, {K[1, 2]}) outside the image")
        D = D.reshape(4)
        # theta -> theta_d must increase on [0, 90 deg], or one pixel would see two directions.
        theta = np.linspace(0.0, HALF_PI, 512)
        if np.any(np.diff(distort_angle(theta, D)) <= 0):
            raise IntrinsicsError(f"D={D.tolist()} folds the image (theta_d not increasing)")
        object.__setattr__(self, "K", K)
        object.__setattr__(self, "D", D)
        object.__setattr__(self, "width", int(self.width))
        object.__setattr__(self, "height", int(self.height))
        fov_x, fov_y = self.fov_rad
        if max(fov_x, fov_y) >= np.pi:
            raise IntrinsicsError(
                f"field of view {np.degrees(fov_x):.0f} x {np.degrees(fov_y):.0f} deg reaches "
                "180 deg: OpenCV's fisheye model only images points in front of the camera"
            )

    @classmethod
    def from_fov(
        cls,
        fov_x_deg: float = PAPER_FOV_DEG[0],
        fov_y_deg: float = PAPER_FOV_DEG[1],
        width: int = PAPER_SIZE[0],
        height: int = PAPER_SIZE[1],
        D=(0.0, 0.0, 0.0, 0.0),
    ) -> FisheyeModel:
        """The camera whose image edges (through the centred principal point) are at
        ``fov_x_deg`` / ``fov_y_deg`` full angle."""
        D = np.asarray(D, dtype=float).reshape(-1)
        if D.shape != (4,):
            raise IntrinsicsError(f"D must hold 4 coefficients k1..k4, got {D.shape}")
        half = np.radians([fov_x_deg, fov_y_deg]) / 2.0
        if not np.all((half > 0) & (half < HALF_PI)):
            raise IntrinsicsError(f"FOV must be in (0, 180) deg, got {fov_x_deg}, {fov_y_deg}")
        cx, cy = (width - 1) / 2.0, (height - 1) / 2.0
        # The outer edge of the edge pixel is half a pixel beyond its centre.
        fx, fy = (width / 2.0, height / 2.0) / distort_angle(half, D)
        return cls(np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]]), D, width, height)

    # -- geometry -------------------------------------------------------------------------
    def angle_of_pixels(self, uv: np.ndarray) -> np.ndarray:
        """``(...)`` incidence angle ``theta`` of pixels ``uv`` ``(..., 2)``; NaN beyond the
        90 deg image circle. Inverts ``theta_d`` by Newton steps from ``theta = theta_d``."""
        uv = np.asarray(uv, dtype=float)
        xd = (uv[..., 0] - self.K[0, 2]) / self.K[0, 0]
        yd = (uv[..., 1] - self.K[1, 2]) / self.K[1, 1]
        theta_d = np.hypot(xd, yd)
        theta = np.minimum(theta_d, HALF_PI)
        for _ in range(20):
            t2 = theta * theta
            f = distort_angle(theta, self.D) - theta_d
            df = 1.0 + t2 * (
                3 * self.D[0] + t2 * (5 * self.D[1] + t2 * (7 * self.D[2] + t2 * 9 * self.D[3]))
            )
            theta = np.clip(theta - f / df, 0.0, HALF_PI)
        return np.where(theta_d < distort_angle(np.array(HALF_PI), self.D), theta, np.nan)

    @property
    def fov_rad(self) -> tuple[float, float]:
        """Horizontal and vertical field of view (outer pixel edges through the principal
        point), radians; ``pi`` when an edge lies beyond the 90 deg image circle."""
        cx, cy = self.K[0, 2], self.K[1, 2]
        edges = np.array([[-0.5, cy], [self.width - 0.5, cy], [cx, -0.5], [cx, self.height - 0.5]])
        theta = np.nan_to_num(self.angle_of_pixels(edges), nan=HALF_PI)
        return float(theta[0] + theta[1]), float(theta[2] + theta[3])

    def unproject(self, uv: np.ndarray) -> np.ndarray:
        """Unit rays ``(..., 3)`` (camera frame) of pixels ``uv`` ``(..., 2)``; NaN beyond the
        image circle. Same as ``cv2.fisheye.undistortPoints`` where that is defined: OpenCV
        clamps ``theta_d`` to 90 deg, which a wide lens with ``k1 > 0`` exceeds in its corners,
        so the angle is inverted here (:meth:`angle_of_pixels`) for every pixel."""
        uv = np.asarray(uv, dtype=float)
        xd = (uv[..., 0] - self.K[0, 2]) / self.K[0, 0]
        yd = (uv[..., 1] - self.K[1, 2]) / self.K[1, 1]
        theta = self.angle_of_pixels(uv)
        theta_d = np.hypot(xd, yd)
        radial = np.where(theta_d > 0, np.sin(theta) / np.maximum(theta_d, 1e-300), 1.0)
        return np.stack([xd * radial, yd * radial, np.cos(theta)], axis=-1)

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit ray ``(H, W, 3)`` of every pixel centre (camera frame) and ``(H, W)`` bool:
        inside the image circle (rays outside are NaN)."""
        v, u = np.mgrid[0 : self.height, 0 : self.width].astype(np.float64)
        rays = self.unproject(np.stack([u, v], axis=-1))
        return rays, np.all(np.isfinite(rays), axis=-1)

    def project(self, points_cam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixels ``(..., 2)`` of camera-frame points ``(..., 3)`` by one
        ``cv2.fisheye.projectPoints`` call, and ``(...)`` bool: in front of the camera
        (OpenCV's model is undefined behind it) and inside the image."""
        p = np.asarray(points_cam, dtype=float)
        flat = np.ascontiguousarray(p.reshape(-1, 1, 3))
        uv, _ = cv2.fisheye.projectPoints(flat, np.zeros(3), np.zeros(3), self.K, self.D)
        uv = uv.reshape(*p.shape[:-1], 2)
        u, v = uv[..., 0], uv[..., 1]
        ok = (
            (p[..., 2] > 0)
            & (u > -0.5)
            & (u < self.width - 0.5)
            & (v > -0.5)
            & (v < self.height - 0.5)
        )
        return uv, ok

    def as_dict(self) -> dict:
        """Self-describing, JSON-ready: model name, image size, K and D (OpenCV conventions)."""
        return {
            "model": self.name,
            "width": self.width,
            "height": self.height,
            "K": self.K.tolist(),
            "D": self.D.tolist(),
            "fov_deg": [float(np.degrees(a)) for a in self.fov_rad],
        }

    def scaled(self, factor: float) -> FisheyeModel:
        """The same lens at ``factor`` times the resolution (pixel centres kept consistent)."""
        width, height = round(self.width * factor), round(self.height * factor)
        sx, sy = width / self.width, height / self.height
        K = self.K.copy()
        K[0, 0] *= sx
        K[1, 1] *= sy
        K[0, 2] = (K[0, 2] + 0.5) * sx - 0.5
        K[1, 2] = (K[1, 2] + 0.5) * sy - 0.5
        return FisheyeModel(K, self.D, width, height, self.name)

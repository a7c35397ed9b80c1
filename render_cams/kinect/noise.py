"""Depth noise of time-of-flight Kinects: axial, lateral, flying pixels, invalid pixels.

Axial noise (along the optical axis) follows the model Fankhauser et al. fitted to the
Kinect V2 ("Kinect v2 for Mobile Robot Navigation: Evaluation and Modeling", ICAR 2015)::

    sigma_z(z, theta) [mm] = a0 + a1 z + a2 z^2 + a3 z^1.5 theta^2 / (pi/2 - theta)^2

with ``z`` the depth in metres and ``theta`` the angle between the viewing ray and the surface
normal; their coefficients are ``(1.5, -0.5, 0.3, 0.1)``. The angle term has the form Nguyen,
Izadi & Lovell derived for the Kinect v1 ("Modeling Kinect Sensor Noise for Improved 3D
Reconstruction and Tracking", 3DIMPVT 2012).

Lateral noise (perpendicular to the ray) uses Nguyen et al.'s pixel-domain fit
``sigma_L [px] = 0.8 + 0.035 theta / (pi/2 - theta)``: depth is sampled at a pixel position
jittered by that sigma, so edges wander by about a pixel as in real depth maps.

Flying pixels: a time-of-flight pixel that sees a foreground edge and the background behind it
integrates both returns and reports a depth in between (Lefloch et al., "Technical foundation
and calibration methods for time-of-flight cameras", 2013). Pixels next to a depth jump larger
than ``edge_jump_m`` take, with probability ``flying_probability``, a depth drawn uniformly
between the two sides.

Invalid pixels read 0, as Kinect depth maps do: outside the sensor's range, at grazing
incidence beyond ``max_incidence_deg`` (too little light returns), and where nothing was hit.

The Azure Kinect uses the same model: Tolgyessy et al. ("Evaluation of the Azure Kinect and
Its Comparison to Kinect V2 and Kinect V1", Sensors 2021) measured a lower depth standard
deviation for the Azure Kinect NFOV mode than for the V2, so the V2 coefficients are a
conservative bound; the Azure hardware specification bounds the random error by 17 mm, which
caps sigma_z.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from render_cams.device import DeviceError

# 4-neighbourhood offsets (dv, du) for edge detection.
_NEIGHBOURS = ((0, 1), (0, -1), (1, 0), (-1, 0))


@dataclass(frozen=True)
class DepthNoiseModel:
    """Parameters of the noise model in the module docstring.

    Attributes:
        axial_mm: ``(a0, a1, a2, a3)`` of sigma_z in mm (z in metres).
        max_axial_mm: cap on sigma_z in mm.
        lateral_px: ``(b0, b1)`` of sigma_L [px] = b0 + b1 theta / (pi/2 - theta); ``(0, 0)``
            switches lateral noise off.
        flying_probability: chance that a pixel on a depth edge becomes a flying pixel.
        edge_jump_m: depth difference to a 4-neighbour that makes a pixel an edge pixel.
        max_incidence_deg: surfaces seen at a larger angle from their normal read invalid.
    """

    axial_mm: tuple[float, float, float, float] = (1.5, -0.5, 0.3, 0.1)
    max_axial_mm: float = 17.0
    lateral_px: tuple[float, float] = (0.8, 0.035)
    flying_probability: float = 0.5
    edge_jump_m: float = 0.1
    max_incidence_deg: float = 80.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.flying_probability <= 1.0):
            raise DeviceError(
                f"flying_probability must be in [0, 1], got {self.flying_probability}"
            )
        if min(self.lateral_px) < 0 or self.edge_jump_m <= 0 or self.max_axial_mm <= 0:
            raise DeviceError("lateral sigma, edge jump and axial cap must be non-negative")
        if not 0.0 < self.max_incidence_deg < 90.0:
            raise DeviceError(f"max_incidence_deg must be in (0, 90), got {self.max_incidence_deg}")

    def axial_sigma_m(self, z: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """Axial standard deviation in metres at depths ``z`` and incidence angles ``theta``
        (radians), any matching shapes."""
        a0, a1, a2, a3 = self.axial_mm
        z = np.asarray(z, float)
        theta = np.clip(np.asarray(theta, float), 0.0, np.radians(self.max_incidence_deg))
        angle_term = theta**2 / (0.5 * np.pi - theta) ** 2
        sigma_mm = a0 + a1 * z + a2 * z**2 + a3 * np.sqrt(np.maximum(z, 0.0)) ** 3 * angle_term
        return np.clip(sigma_mm, 0.0, self.max_axial_mm) * 1e-3

    def lateral_sigma_px(self, theta: np.ndarray) -> np.ndarray:
        """Lateral standard deviation in pixels at incidence angles ``theta`` (radians)."""
        b0, b1 = self.lateral_px
        theta = np.clip(np.asarray(theta, float), 0.0, np.radians(self.max_incidence_deg))
        return b0 + b1 * theta / (0.5 * np.pi - theta)

    def apply(
        self,
        depth: np.ndarray,
        K: np.ndarray,
        range_m: tuple[float, float],
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, np.ndarray]:
        """A noisy depth map from a clean one, and the source pixel of every output pixel.

        Args:
            depth: ``(H, W)`` clean depth in metres, 0 where nothing was hit.
            K: ``(3, 3)`` intrinsics.
            range_m: ``(near, far)``; depth outside reads 0.
            rng: randomness.

        Returns:
            ``(H, W)`` float64 noisy depth in metres (0 = invalid) and ``(H, W)`` int64 flat
            index of the pixel each output pixel was sampled from (lateral noise), so that
            other per-pixel maps (body index) move with the depth.
        """
        depth = np.asarray(depth, float)
        h, w = depth.shape
        theta = incidence_angles(depth, K)
        sigma_l = self.lateral_sigma_px(theta)
        v, u = np.mgrid[0:h, 0:w]
        src_u = np.clip(np.rint(u + rng.standard_normal((h, w)) * sigma_l), 0, w - 1).astype(int)
        src_v = np.clip(np.rint(v + rng.standard_normal((h, w)) * sigma_l), 0, h - 1).astype(int)
        source = src_v * w + src_u
        z = depth.ravel()[source]
        theta = theta.ravel()[source]

        z = self._flying_pixels(z, rng)
        noisy = z + rng.standard_normal(z.shape) * self.axial_sigma_m(z, theta)
        near, far = range_m
        grazing = theta > np.radians(self.max_incidence_deg)
        invalid = (z <= 0) | (noisy < near) | (noisy > far) | grazing
        return np.where(invalid, 0.0, noisy), source

    def _flying_pixels(self, z: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """``z`` with edge pixels (valid on both sides of a jump) mixed towards the far side."""
        other = depth_edge_partner(z, self.edge_jump_m)
        flying = (other > 0) & (rng.random(z.shape) < self.flying_probability)
        mix = rng.random(z.shape)
        return np.where(flying, z + mix * (other - z), z)


def depth_edge_partner(depth: np.ndarray, jump_m: float) -> np.ndarray:
    """``(H, W)`` depth of the 4-neighbour across the largest depth jump above ``jump_m``
    (both pixels valid), 0 where a pixel is not on such an edge."""
    padded = np.pad(depth, 1)
    h, w = depth.shape
    partner = np.zeros_like(depth)
    best = np.full_like(depth, jump_m)
    for dv, du in _NEIGHBOURS:
        neighbour = padded[1 + dv : 1 + dv + h, 1 + du : 1 + du + w]
        jump = np.abs(neighbour - depth)
        take = (depth > 0) & (neighbour > 0) & (jump > best)
        partner = np.where(take, neighbour, partner)
        best = np.where(take, jump, best)
    return partner


def incidence_angles(depth: np.ndarray, K: np.ndarray) -> np.ndarray:
    """``(H, W)`` angle (radians) between each pixel's viewing ray and its surface normal.

    With the ray ``r = ((u - cx) / fx, (v - cy) / fy, 1)`` and the point ``z r``, the normal is
    ``n = (-fx dz/du, -fy dz/dv, fx r_x dz/du + fy r_y dz/dv + z)`` and ``n . r = z``, so
    ``cos(theta) = z / (|n| |r|)``. Depth derivatives use the one-sided difference with the
    smaller change, so a pixel on a depth edge gets the normal of its own surface rather than
    of the jump. 0 where the depth is 0.
    """
    depth = np.asarray(depth, float)
    h, w = depth.shape
    rx = ((np.arange(w) - K[0, 2]) / K[0, 0])[None, :]
    ry = ((np.arange(h) - K[1, 2]) / K[1, 1])[:, None]
    du = K[0, 0] * _smooth_difference(depth, axis=1)
    dv = K[1, 1] * _smooth_difference(depth, axis=0)
    normal_z = rx * du + ry * dv + depth
    normal_norm = np.sqrt(du * du + dv * dv + normal_z * normal_z)
    ray_norm = np.sqrt(rx * rx + ry * ry + 1.0)
    cos = depth / np.maximum(normal_norm * ray_norm, 1e-12)
    return np.where(depth > 0, np.arccos(np.clip(cos, 0.0, 1.0)), 0.0)


def _smooth_difference(depth: np.ndarray, axis: int) -> np.ndarray:
    """``(H, W)`` forward or backward depth difference along image ``axis``, whichever is
    smaller in magnitude (the only one there is at the image border)."""
    step = np.diff(depth, axis=axis)
    first = [slice(None)] * 2
    last = [slice(None)] * 2
    first[axis], last[axis] = slice(0, 1), slice(-1, None)
    forward = np.concatenate([step, step[tuple(last)]], axis=axis)
    backward = np.concatenate([step[tuple(first)], step], axis=axis)
    return np.where(np.abs(forward) <= np.abs(backward), forward, backward)


KINECT_V2_NOISE = DepthNoiseModel()
"""Fankhauser et al. 2015 axial coefficients, Nguyen et al. 2012 lateral fit."""
AZURE_KINECT_NOISE = DepthNoiseModel()
"""Same model (see the module docstring for why), capped at the 17 mm spec bound."""

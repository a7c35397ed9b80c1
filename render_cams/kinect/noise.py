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
from functools import lru_cache

import numpy as np

from avatarsim.render_cams.device import DeviceError

# 4-neighbour offsets (dv, du) for edge detection; ties go to the first.
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

    @property
    def _max_ratio(self) -> np.float32:
        """The angle ratio ``theta / (pi/2 - theta)`` at ``max_incidence_deg``."""
        theta = np.radians(self.max_incidence_deg)
        return np.float32(theta / (0.5 * np.pi - theta))

    @staticmethod
    def _angle_ratio(theta: np.ndarray) -> np.ndarray:
        """``theta / (pi/2 - theta)`` (growing with theta, inf at pi/2); float32 stays float32."""
        theta = np.asarray(theta, np.result_type(theta, np.float32))
        with np.errstate(divide="ignore"):
            return theta / (np.pi / 2 - theta)

    def axial_sigma_m(self, z: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """Axial standard deviation in metres at depths ``z`` and incidence angles ``theta``
        (radians, clipped to ``max_incidence_deg``), any matching shapes."""
        return self._axial_sigma_of_ratio(np.asarray(z), self._angle_ratio(theta))

    def _axial_sigma_of_ratio(self, z: np.ndarray, ratio: np.ndarray) -> np.ndarray:
        a0, a1, a2, a3 = self.axial_mm
        z = np.asarray(z, np.result_type(z, np.float32))
        ratio = np.minimum(ratio, self._max_ratio)
        angle_term = np.sqrt(np.maximum(z, 0.0))
        angle_term *= z  # z^1.5
        angle_term *= ratio * ratio
        sigma_mm = a0 + z * (a1 + a2 * z)
        sigma_mm += a3 * angle_term
        return np.clip(sigma_mm, 0.0, self.max_axial_mm) * 1e-3

    def lateral_sigma_px(self, theta: np.ndarray) -> np.ndarray:
        """Lateral standard deviation in pixels at incidence angles ``theta`` (radians, clipped
        to ``max_incidence_deg``)."""
        return self._lateral_sigma_of_ratio(self._angle_ratio(theta))

    def _lateral_sigma_of_ratio(self, ratio: np.ndarray) -> np.ndarray:
        b0, b1 = self.lateral_px
        return b0 + b1 * np.minimum(ratio, self._max_ratio)

    def apply(
        self,
        depth: np.ndarray,
        K: np.ndarray,
        range_m: tuple[float, float],
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, np.ndarray]:
        """A noisy depth map from a clean one, and the source pixel of every output pixel.

        Computed in float32 (depth noise is >= 1 mm; float32 resolves 0.5 um at 4.5 m); the
        axial noise only where the sampled depth is valid.

        Args:
            depth: ``(H, W)`` clean depth in metres, 0 where nothing was hit.
            K: ``(3, 3)`` intrinsics.
            range_m: ``(near, far)``; depth outside reads 0.
            rng: randomness.

        Returns:
            ``(H, W)`` float32 noisy depth in metres (0 = invalid) and ``(H, W)`` intp flat
            index of the pixel each output pixel was sampled from (lateral noise), so that
            other per-pixel maps (body index) move with the depth.
        """
        depth = np.asarray(depth, np.float32)
        h, w = depth.shape
        # theta / (pi/2 - theta) per pixel: both sigmas depend on theta only through it.
        ratio = self._angle_ratio(incidence_angles(depth, K))
        jitter = standard_normal(rng, (2, h, w))
        jitter *= self._lateral_sigma_of_ratio(ratio)
        jitter += _pixel_grid(h, w)  # (row, column) of the sampled position
        np.rint(jitter, out=jitter)
        src_v = np.clip(jitter[0], 0, h - 1, out=jitter[0]).astype(np.intp)
        src_u = np.clip(jitter[1], 0, w - 1, out=jitter[1]).astype(np.intp)
        src_v *= w
        source = np.add(src_v, src_u, out=src_v)
        z = depth.ravel()[source]
        self._add_flying_pixels(z, rng)

        valid = np.flatnonzero(z)  # sampled a surface
        z_valid = z.ravel()[valid]
        ratio_valid = ratio.ravel()[source.ravel()[valid]]
        measured = standard_normal(rng, len(valid))
        measured *= self._axial_sigma_of_ratio(z_valid, ratio_valid)
        measured += z_valid
        near, far = range_m
        grazing = ratio_valid > self._max_ratio
        measured[(measured < near) | (measured > far) | grazing] = 0.0
        noisy = np.zeros((h, w), np.float32)
        noisy.ravel()[valid] = measured
        return noisy, source

    def _add_flying_pixels(self, z: np.ndarray, rng: np.random.Generator) -> None:
        """Mix edge pixels of ``z`` (valid on both sides of a jump) towards the far side, in
        place; random numbers are drawn for edge pixels only."""
        index, other = _edge_partners(z, self.edge_jump_m)
        flying = rng.random(len(index), dtype=np.float32) < self.flying_probability
        index, other = index[flying], other[flying]
        flat = z.reshape(-1)
        near_side = flat[index]
        flat[index] = near_side + rng.random(len(index), dtype=np.float32) * (other - near_side)


def standard_normal(rng: np.random.Generator, shape: int | tuple[int, ...]) -> np.ndarray:
    """float32 standard normal samples of ``shape``, by the Box-Muller transform of float32
    uniforms (pairs ``sqrt(-2 ln(1 - u1)) (cos, sin)(2 pi u2)``).

    Why not ``rng.standard_normal(dtype=np.float32)``: here it is ~2.5x slower, and three
    normals per pixel were a third of a Kinect frame. The uniforms' 24-bit resolution caps
    ``|n|`` at 5.8 (a normal exceeds that with probability 7e-9).
    """
    n = int(np.prod(shape))
    half = (n + 1) // 2
    u = rng.random((2, half), dtype=np.float32)
    radius = np.log1p(-u[0])
    radius *= -2.0
    np.sqrt(radius, out=radius)
    angle = u[1]
    angle *= np.float32(2.0 * np.pi)
    out = np.empty(2 * half, np.float32)
    np.multiply(radius, np.cos(angle), out=out[:half])
    np.multiply(radius, np.sin(angle), out=out[half:])
    return out[:n].reshape(shape)


def _edge_partners(depth: np.ndarray, jump_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices ``(N,)`` of pixels on a depth edge (a jump above ``jump_m`` to a valid
    4-neighbour) and ``(N,)`` the depth of the neighbour across the largest such jump.

    One shifted difference per image axis finds the edges; only the (few) pixels on them are
    then compared with their four neighbours.
    """
    h, w = depth.shape
    # NaN for "no depth": every comparison with it is False, so no jump to or from it counts.
    surface = np.where(depth > 0, depth, np.float32(np.nan))
    with np.errstate(invalid="ignore"):
        across_columns = np.abs(np.diff(surface, axis=1)) > jump_m
        across_rows = np.abs(np.diff(surface, axis=0)) > jump_m
    on_edge = np.zeros((h, w), bool)
    on_edge[:, :-1] |= across_columns
    on_edge[:, 1:] |= across_columns
    on_edge[:-1] |= across_rows
    on_edge[1:] |= across_rows
    index = np.flatnonzero(on_edge)
    rows, cols = np.divmod(index, w)
    padded = np.pad(surface, 1, constant_values=np.nan)  # no neighbour beyond the border
    offsets = np.array([dv * (w + 2) + du for dv, du in _NEIGHBOURS])
    neighbours = padded.ravel()[((rows + 1) * (w + 2) + cols + 1)[:, None] + offsets]  # (N, 4)
    jumps = np.nan_to_num(np.abs(neighbours - surface.ravel()[index, None]), nan=-1.0)
    return index, neighbours[np.arange(len(index)), np.argmax(jumps, axis=1)]


def depth_edge_partner(depth: np.ndarray, jump_m: float) -> np.ndarray:
    """``(H, W)`` depth of the 4-neighbour across the largest depth jump above ``jump_m``
    (both pixels valid), 0 where a pixel is not on such an edge."""
    depth = np.asarray(depth)
    index, other = _edge_partners(depth, jump_m)
    partner = np.zeros_like(depth)
    partner.ravel()[index] = other
    return partner


@lru_cache(maxsize=8)
def _pixel_grid(h: int, w: int) -> np.ndarray:
    """``(2, H, W)`` float32 row and column of every pixel (read-only, shared)."""
    grid = np.stack(np.mgrid[0:h, 0:w]).astype(np.float32)
    grid.flags.writeable = False
    return grid


@lru_cache(maxsize=8)
def _ray_tables(
    K_key: tuple[float, float, float, float], h: int, w: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(1, W)`` ray x, ``(H, 1)`` ray y (camera z = 1) and ``(H, W)`` ray length, float32."""
    fx, fy, cx, cy = K_key
    rx = ((np.arange(w) - cx) / fx)[None, :]
    ry = ((np.arange(h) - cy) / fy)[:, None]
    tables = (rx, ry, np.sqrt(rx * rx + ry * ry + 1.0))
    return tuple(t.astype(np.float32) for t in tables)


def incidence_angles(depth: np.ndarray, K: np.ndarray) -> np.ndarray:
    """``(H, W)`` angle (radians) between each pixel's viewing ray and its surface normal.

    With the ray ``r = ((u - cx) / fx, (v - cy) / fy, 1)`` and the point ``z r``, the normal is
    ``n = (-fx dz/du, -fy dz/dv, fx r_x dz/du + fy r_y dz/dv + z)`` and ``n . r = z``, so
    ``cos(theta) = z / (|n| |r|)``. Depth derivatives use the one-sided difference with the
    smaller change, so a pixel on a depth edge gets the normal of its own surface rather than
    of the jump. 0 where the depth is 0. Float32 in, float32 out.
    """
    depth = np.asarray(depth, np.result_type(depth, np.float32))
    h, w = depth.shape
    rx, ry, ray_norm = _ray_tables((K[0, 0], K[1, 1], K[0, 2], K[1, 2]), h, w)
    du = _smooth_difference(depth, axis=1)
    du *= K[0, 0]
    dv = _smooth_difference(depth, axis=0)
    dv *= K[1, 1]
    normal_z = rx * du + ry * dv + depth
    length = du * du
    length += dv * dv
    length += normal_z * normal_z
    np.sqrt(length, out=length)
    length *= ray_norm
    cos = np.divide(depth, np.maximum(length, 1e-12, out=length), out=length)
    theta = np.arccos(np.clip(cos, 0.0, 1.0, out=cos), out=cos)
    theta[depth <= 0] = 0.0
    return theta


def _smooth_difference(depth: np.ndarray, axis: int) -> np.ndarray:
    """``(H, W)`` forward or backward depth difference along image ``axis``, whichever is
    smaller in magnitude (the only one there is at the image border)."""
    step = np.moveaxis(np.diff(depth, axis=axis), axis, 0)  # (n - 1, m): differences first
    out = np.empty(depth.shape, depth.dtype)
    view = np.moveaxis(out, axis, 0)
    size = np.abs(step)
    forward_smaller = size[1:] <= size[:-1]  # at interior position i: step[i] vs step[i - 1]
    view[1:-1] = np.where(forward_smaller, step[1:], step[:-1])
    view[0], view[-1] = step[0], step[-1]
    return out


KINECT_V2_NOISE = DepthNoiseModel()
"""Fankhauser et al. 2015 axial coefficients, Nguyen et al. 2012 lateral fit."""
AZURE_KINECT_NOISE = DepthNoiseModel()
"""Same model (see the module docstring for why), capped at the 17 mm spec bound."""

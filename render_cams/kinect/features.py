"""Shotton's depth-comparison features on a Kinect depth frame (CVPR 2011, section 3, eq. 1).

``f(x) = d(x + u / d(x)) - d(x + v / d(x))``: the depth difference of two probe pixels whose
offsets from pixel ``x`` shrink with the depth ``d(x)`` of ``x``, so a feature reads the same
body point whatever the person's distance. Here an offset is given in metres across the image
plane at the pixel's depth (``u_px = f * u_m / d(x)``, with the sensor's focal lengths), which
is Shotton's pixel-metre offset divided by the focal length: a feature then means the same
on every sensor mode. Probes that leave the image or land off the body read
:data:`BACKGROUND_M` ("a large positive constant", Shotton section 3), so the silhouette is
part of every feature. Half the features are unary (``v = 0``: ``d(x + u / d(x)) - d(x)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BACKGROUND_M = 10.0
"""Depth read by probes off the body or outside the image."""


@dataclass(frozen=True)
class DepthFeatures:
    """``F`` feature offset pairs ``u, v (F, 2)``: metres across the image plane (x right,
    y down), at the depth of the probed pixel."""

    u: np.ndarray
    v: np.ndarray

    @classmethod
    def sample(cls, n: int, max_offset_m: float, rng: np.random.Generator) -> DepthFeatures:
        """``n`` features with offsets uniform in the disc of radius ``max_offset_m``; the
        second half unary."""
        radius = max_offset_m * np.sqrt(rng.random((2, n)))
        angle = rng.random((2, n)) * 2.0 * np.pi
        offsets = np.stack([radius * np.cos(angle), radius * np.sin(angle)], -1)  # (2, n, 2)
        offsets[1, n // 2 :] = 0.0
        return cls(offsets[0], offsets[1])

    def __len__(self) -> int:
        return len(self.u)

    def evaluate(
        self, depth: np.ndarray, K: np.ndarray, rows: np.ndarray, cols: np.ndarray, index
    ) -> np.ndarray:
        """Feature values (metres) at pixels ``(rows, cols)`` ``(N,)``.

        Args:
            depth: ``(H, W)`` float depth in metres of the body, :data:`BACKGROUND_M`
                elsewhere (:func:`body_depth`).
            K: ``(3, 3)`` intrinsics of ``depth``.
            index: feature indices, ``(N,)`` (one per pixel) or ``(N, F')`` (a block each).
        """
        index = np.asarray(index)
        d = depth[rows, cols]
        shape = (len(rows),) + (1,) * (index.ndim - 1)
        return self._probe(depth, K, rows, cols, d, self.u[index], shape) - self._probe(
            depth, K, rows, cols, d, self.v[index], shape
        )

    @staticmethod
    def _probe(depth, K, rows, cols, d, offset, shape) -> np.ndarray:
        h, w = depth.shape
        scale = 1.0 / d.reshape(shape)
        r = np.rint(rows.reshape(shape) + K[1, 1] * offset[..., 1] * scale).astype(np.intp)
        c = np.rint(cols.reshape(shape) + K[0, 0] * offset[..., 0] * scale).astype(np.intp)
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        values = depth[np.clip(r, 0, h - 1), np.clip(c, 0, w - 1)]
        return np.where(inside, values, BACKGROUND_M)


def body_depth(depth_mm: np.ndarray, body_index: np.ndarray) -> np.ndarray:
    """``(H, W)`` float32 metres on the body (body index 0 with a reading; NaN and 0 depth
    count as no reading), :data:`BACKGROUND_M` elsewhere."""
    depth = np.asarray(depth_mm, np.float32) * np.float32(1e-3)
    body = (np.asarray(body_index) == 0) & np.isfinite(depth) & (depth > 0)
    return np.where(body, depth, np.float32(BACKGROUND_M))

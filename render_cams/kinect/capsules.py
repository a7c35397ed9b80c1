"""The body as posed capsules, for ray tests (joint occlusion) and inside-body checks.

Every segment of :class:`~avatar_models.body.BodyDescription` becomes a capsule: capsules stay
capsules, the skull sphere is a capsule of zero length, a foot box is a capsule along its
longest axis with the smaller of its two other half extents as radius (inside the box).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body import BodyDescription


@dataclass(frozen=True)
class PosedCapsules:
    """Capsule axes over time: ``start, end (T, S, 3)`` world metres, ``radius (S,)``."""

    start: np.ndarray
    end: np.ndarray
    radius: np.ndarray

    def distance_to_points(self, points: np.ndarray) -> np.ndarray:
        """``(T, N, S)`` distance from ``points (T, N, 3)`` to each capsule's axis."""
        p = points[:, :, None]
        a, b = self.start[:, None], self.end[:, None]
        ab = b - a
        t = np.clip(np.sum((p - a) * ab, -1) / np.maximum(np.sum(ab * ab, -1), 1e-12), 0, 1)
        return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)

    def distance_to_segments(self, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
        """``(T, N, S)`` distance from segments ``p0 (T, 1 or N, 3)`` -> ``p1 (T, N, 3)`` to
        each capsule's axis (closest points of two segments, Ericson 2005, section 5.1.9)."""
        d1 = (p1 - p0)[:, :, None]
        d2 = (self.end - self.start)[:, None]
        r = p0[:, :, None] - self.start[:, None]
        a = np.maximum(np.sum(d1 * d1, -1), 1e-12)
        e = np.sum(d2 * d2, -1)
        f = np.sum(d2 * r, -1)
        c = np.sum(d1 * r, -1)
        b = np.sum(d1 * d2, -1)
        denom = a * e - b * b
        safe_e = np.maximum(e, 1e-12)
        s = np.where(denom > 1e-12, np.clip((b * f - c * e) / np.maximum(denom, 1e-12), 0, 1), 0)
        t = (b * s + f) / safe_e
        # Clamp t to the capsule axis and recompute s for the clamped t.
        s = np.where(t < 0, np.clip(-c / a, 0, 1), np.where(t > 1, np.clip((b - c) / a, 0, 1), s))
        t = np.where(e > 1e-12, np.clip(t, 0, 1), 0)
        closest1 = p0[:, :, None] + s[..., None] * d1
        closest2 = self.start[:, None] + t[..., None] * d2
        return np.linalg.norm(closest1 - closest2, axis=-1)


def posed_capsules(body: BodyDescription, motion: Motion) -> PosedCapsules:
    """The capsules of ``body`` posed by every frame of ``motion`` (same skeleton)."""
    starts, ends, radii, bodies = [], [], [], []
    for seg in body.segments:
        if seg.shape == "box":
            axis = int(np.argmax(seg.half_extents))
            others = np.delete(seg.half_extents, axis)
            radius = float(others.min())
            half = seg.box_rotation[:, axis] * max(seg.half_extents[axis] - radius, 0.0)
            start, end = seg.start - half, seg.start + half
        else:
            start, end, radius = seg.start, seg.end, seg.radius
        starts.append(start)
        ends.append(end)
        radii.append(radius)
        bodies.append(seg.body)
    positions, rotations = motion.fk()
    pos, rot = positions[:, bodies], rotations[:, bodies]
    return PosedCapsules(
        start=pos + np.einsum("tsab,sb->tsa", rot, np.array(starts)),
        end=pos + np.einsum("tsab,sb->tsa", rot, np.array(ends)),
        radius=np.array(radii),
    )

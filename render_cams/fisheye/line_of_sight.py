"""Which body17 joints a camera can see past the body: per-ray depth of a joint inside its
own limbs, and a ray test against the body geometry.

A joint sits inside its limbs, so the surface a camera sees at a joint's pixel is in front of
the joint by the length of the ray's path through the segments that meet at that joint (the
segments carried by its body and by its parent's: the shank and foot at the ankle, the upper
arm and forearm at the elbow). That path depends on the ray: a ray along the shin from above
crosses much more of it than one straight through. :func:`own_depth` measures it by sampling
the ray back from the joint towards the camera; a joint is hidden when something nearer than
that path's entry is in the way:

- from a rendered range image (:func:`render_cams.fisheye.keypoints.visibility`): the range
  seen at the joint's pixel is shorter than the joint's range minus its own depth;
- from the geometry alone (:func:`occluded`, for paths that render nothing): the line from
  the camera to that entry meets any other segment.

Both are vectorised over frames and joints; :data:`STEP_M` is the sampling step.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import BodyDescription
from avatarsim.render_cams.fisheye.rig import inside_segments

STEP_M = 0.01
"""Sampling step along a ray (the ray test's resolution)."""
MAX_OWN_DEPTH_M = 0.4
"""Longest path through a joint's own limbs that is searched (a foot seen end-on)."""


def own_segments(body: BodyDescription) -> np.ndarray:
    """``(17, S)`` bool: the segments that meet at each body17 joint (carried by its body or
    its parent's)."""
    joints = body.rig.body17_indices(body.skeleton)
    parents = body.skeleton.parents
    carried = np.array([s.body for s in body.segments])
    return np.stack([(carried == j) | (carried == parents[j]) for j in joints])


def _ray_samples(centres: np.ndarray, joints: np.ndarray, distances: np.ndarray) -> np.ndarray:
    """``(T, J, K, 3)`` points at ``distances`` ``(T, J, K)`` from the joints ``(T, J, 3)``
    back towards the camera centres ``(T, 3)``."""
    back = centres[:, None] - joints
    back /= np.maximum(np.linalg.norm(back, axis=-1, keepdims=True), 1e-12)
    return joints[:, :, None] + distances[..., None] * back[:, :, None]


def own_depth(
    body: BodyDescription,
    positions: np.ndarray,
    rotations: np.ndarray,
    centres: np.ndarray,
    joints: np.ndarray,
) -> np.ndarray:
    """``(T, J)`` metres: length of the ray from each joint towards the camera that stays inside
    the joint's own segments (0 for a joint outside them).

    Args:
        positions, rotations: ``(T, J_rig, 3)``, ``(T, J_rig, 3, 3)`` global pose of the rig.
        centres: ``(T, 3)`` camera centres; joints: ``(T, 17, 3)`` body17 joints.
    """
    n_t, n_j = joints.shape[:2]
    ranges = np.linalg.norm(centres[:, None] - joints, axis=-1)  # (T, J)
    steps = np.arange(int(np.ceil(MAX_OWN_DEPTH_M / STEP_M)) + 1) * STEP_M  # (K,)
    distances = np.minimum(steps, ranges[..., None])  # never behind the camera
    points = _ray_samples(centres, joints, distances)  # (T, J, K, 3)
    inside = inside_segments(body, positions, rotations, points.reshape(n_t, -1, 3))
    inside = inside.reshape(n_t, n_j, len(steps), -1)
    mine = np.any(inside & own_segments(body)[None, :, None], axis=-1)  # (T, J, K)
    run = np.cumprod(mine, axis=-1).sum(axis=-1)  # leading samples inside, from the joint
    return np.where(run > 0, np.minimum((run - 1) * STEP_M, ranges), 0.0)


def _segment_distance(p0, d1, q0, d2) -> np.ndarray:
    """``(...)`` closest distance between segments ``p0 + s d1`` and ``q0 + t d2`` (``s, t`` in
    ``[0, 1]``; arrays ``(..., 3)`` broadcasting), Ericson's clamped closed form."""
    r = p0 - q0
    a = np.einsum("...k,...k->...", d1, d1)
    e = np.einsum("...k,...k->...", d2, d2)
    b = np.einsum("...k,...k->...", d1, d2)
    c = np.einsum("...k,...k->...", d1, r)
    f = np.einsum("...k,...k->...", d2, r)
    denom = a * e - b * b
    safe_a, safe_e = np.maximum(a, 1e-12), np.maximum(e, 1e-12)
    s = np.where(denom > 1e-12, np.clip((b * f - c * e) / np.maximum(denom, 1e-12), 0, 1), 0.0)
    t = np.clip((b * s + f) / safe_e, 0.0, 1.0)
    s = np.clip((b * t - c) / safe_a, 0.0, 1.0)
    gap = p0 + s[..., None] * d1 - q0 - t[..., None] * d2
    return np.linalg.norm(gap, axis=-1)


def _crosses_box(p0, p1, half) -> np.ndarray:
    """``(...)`` bool: segment ``p0 -> p1`` (box frame, ``(..., 3)``) meets the box of half
    sizes ``half`` ``(..., 3)`` (slab test)."""
    d = p1 - p0
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (-half - p0) / d, (half - p0) / d
    flat = np.abs(d) < 1e-12  # parallel to a slab: inside it or never
    inside = np.abs(p0) < half
    lo = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(t0, t1))
    hi = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(t0, t1))
    enter, leave = np.max(lo, axis=-1), np.min(hi, axis=-1)
    return (enter <= leave) & (leave >= 0.0) & (enter <= 1.0)


def occluded(
    body: BodyDescription,
    positions: np.ndarray,
    rotations: np.ndarray,
    centres: np.ndarray,
    joints: np.ndarray,
) -> np.ndarray:
    """``(T, J)`` bool: another segment cuts the line of sight from the camera to the joint
    (arguments as :func:`own_depth`): the segment from the camera to where the ray enters the
    joint's own limbs meets a body segment that does not meet at the joint (capsules and
    spheres by their axis distance, boxes by a slab test)."""
    seg = body.segments
    bodies = np.array([s.body for s in seg])
    rot = rotations[:, bodies]  # (T, S, 3, 3)
    origin = positions[:, bodies]  # (T, S, 3)
    start = origin + np.einsum("tsab,sb->tsa", rot, np.stack([s.start for s in seg]))
    end = origin + np.einsum("tsab,sb->tsa", rot, np.stack([s.end for s in seg]))
    back = centres[:, None] - joints  # (T, J, 3)
    ranges = np.linalg.norm(back, axis=-1)
    depth = own_depth(body, positions, rotations, centres, joints) + STEP_M
    entry = joints + back * (np.minimum(depth, ranges) / np.maximum(ranges, 1e-12))[..., None]
    ray0 = centres[:, None, None]  # (T, 1, 1, 3)
    ray = entry[:, :, None] - ray0  # (T, J, 1, 3)
    radius = np.array([s.radius for s in seg])
    hit = _segment_distance(ray0, ray, start[:, None], (end - start)[:, None]) < radius
    is_box = np.array([s.shape == "box" for s in seg])
    if np.any(is_box):
        box_rot = rot[:, is_box] @ np.stack([s.box_rotation for s in seg if s.shape == "box"])
        centre = start[:, is_box][:, None]  # (T, 1, B, 3)
        local0 = np.einsum("tbka,tjbk->tjba", box_rot, ray0 - centre)  # R^T (p - c)
        local1 = np.einsum("tbka,tjbk->tjba", box_rot, entry[:, :, None] - centre)
        half = np.stack([s.half_extents for s in seg if s.shape == "box"])
        hit[..., is_box] = _crosses_box(local0, local1, half)
    return np.any(hit & ~own_segments(body)[None], axis=-1)

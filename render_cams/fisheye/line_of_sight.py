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
- from the geometry alone (:func:`occluded`, for paths that render nothing): a sample of the
  ray between the camera and that entry lies inside any other segment.

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


def occluded(
    body: BodyDescription,
    positions: np.ndarray,
    rotations: np.ndarray,
    centres: np.ndarray,
    joints: np.ndarray,
) -> np.ndarray:
    """``(T, J)`` bool: another segment cuts the line of sight from the camera to the joint
    (arguments as :func:`own_depth`): a ray sample between the camera and the joint's own
    limbs lies inside a segment that does not meet at the joint."""
    n_t, n_j = joints.shape[:2]
    ranges = np.linalg.norm(centres[:, None] - joints, axis=-1)
    start = own_depth(body, positions, rotations, centres, joints) + STEP_M
    n_k = max(int(np.ceil(ranges.max() / STEP_M)), 1)
    share = (np.arange(n_k) + 0.5) / n_k  # (K,), the camera centre itself excluded
    distances = start[..., None] + share * np.maximum(ranges - start, 0.0)[..., None]
    points = _ray_samples(centres, joints, distances)
    inside = inside_segments(body, positions, rotations, points.reshape(n_t, -1, 3))
    inside = inside.reshape(n_t, n_j, n_k, -1) & ~own_segments(body)[None, :, None]
    return np.any(inside, axis=(-1, -2))

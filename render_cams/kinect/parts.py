"""The body-part set of the Kinect tracker and its per-pixel label image.

Shotton et al. (CVPR 2011, section 2.2) paint 31 parts on their synthetic bodies, some
"defined to directly localise particular skeletal joints of interest" (elbow, wrist, knee,
ankle...), others to fill the space between them; a joint proposal is the mode of its part's
pixels pushed into the body (their section 4). This set keeps only the joint-localising kind:
part ``k + 1`` is the surface around body17 joint ``k`` (:data:`PART_NAMES`), and 0 is no
body. 17 parts instead of 31 because every joint the tracker reports is built from the body17
joints (:mod:`.rig_joints`), so a part between two joints would only be a class to tell apart,
with fewer training pixels per class, that yields no proposal.

A body point takes the part of the nearest (rest pose) body17 joint among those its segment
may touch (:data:`CANDIDATES`: a forearm point belongs to the elbow or the wrist, never to
the hip it passes in an arms-down rest pose), so parts are fixed on the surface and move with
it, as in Shotton's renders. The label image is computed per pixel (:func:`part_image`):
each body pixel of a clean render is reprojected with its depth, carried back into its
segment's rest frame, and labelled there. Painting labels on mesh vertices instead would
follow the tessellation: a capsule's flat sides are single triangles from joint to joint,
and a flat-shaded triangle takes one vertex's label.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.scene import BodyScene

PART_NONE = 0
"""Label of pixels without a body part."""
PART_NAMES: tuple[str, ...] = BODY17
"""Part ``k + 1`` surrounds body17 joint ``PART_NAMES[k]``."""
N_PARTS = len(PART_NAMES)


def _sided(side: str, *joints: str) -> tuple[str, ...]:
    s = side[0]
    return tuple(f"{s}_{j}" for j in joints)


CANDIDATES: dict[tuple[str, str], tuple[str, ...]] = {
    ("head", "center"): ("head", "neck"),
    ("pelvis", "center"): ("pelvis", "l_hip", "r_hip"),
    ("torso", "center"): ("neck", "pelvis", "l_shoulder", "r_shoulder", "l_hip", "r_hip"),
    **{("torso", side): ("neck", *_sided(side, "shoulder")) for side in ("left", "right")},
    **{("pelvis", side): ("pelvis", *_sided(side, "hip")) for side in ("left", "right")},
    **{("upper_arm", side): _sided(side, "shoulder", "elbow") for side in ("left", "right")},
    **{("forearm", side): _sided(side, "elbow", "wrist") for side in ("left", "right")},
    **{("hand", side): _sided(side, "wrist") for side in ("left", "right")},
    **{("thigh", side): _sided(side, "hip", "knee") for side in ("left", "right")},
    **{("shank", side): _sided(side, "knee", "ankle") for side in ("left", "right")},
    **{("foot", side): _sided(side, "ankle", "foot") for side in ("left", "right")},
}
"""(segment kind, side) -> the body17 joints whose parts its surface may belong to."""


def segment_candidates(kind: str, side: str) -> np.ndarray:
    """Body17 indices a segment of ``kind`` on ``side`` may be labelled with."""
    names = CANDIDATES.get((kind, side)) or CANDIDATES[(kind, "center")]
    return np.array([INDEX[n] for n in names])


def candidate_table(body: BodyDescription) -> np.ndarray:
    """``(S, C)`` body17 candidates of each of ``body``'s ``S`` segments, padded with -1."""
    rows = [segment_candidates(s.kind, s.side) for s in body.segments]
    table = np.full((len(rows), max(len(r) for r in rows)), -1)
    for k, r in enumerate(rows):
        table[k, : len(r)] = r
    return table


def rest_parts(body: BodyDescription, rest_points: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """``(N,)`` uint8 part labels (1..17) of body points.

    Args:
        rest_points: ``(N, 3)`` positions in the rest pose (root joint at the origin).
        segment: ``(N,)`` index into ``body.segments`` of each point's segment.
    """
    skeleton = body.skeleton
    rest = skeleton.rest_positions()
    b17_rest = rest[identify_rig(skeleton).body17_indices(skeleton)]  # (17, 3)
    candidates = candidate_table(body)[segment]  # (N, C)
    dist = np.linalg.norm(rest_points[:, None] - b17_rest[candidates], axis=-1)
    dist[candidates < 0] = np.inf
    best = candidates[np.arange(len(segment)), np.argmin(dist, axis=1)]
    return (best + 1).astype(np.uint8)


def part_image(
    scene: BodyScene,
    depth: np.ndarray,
    segments: np.ndarray,
    K: np.ndarray,
    camera_to_world: np.ndarray,
) -> np.ndarray:
    """``(H, W)`` uint8 part labels (:data:`PART_NONE` off the body) of a clean render of
    ``scene`` as posed now.

    Args:
        depth: ``(H, W)`` camera-z metres of the render.
        segments: ``(H, W)`` its segment labels (0 background, ``k + 1`` segment ``k``;
            :meth:`BodyScene.render_depth_and_parts`).
        K: ``(3, 3)`` intrinsics; camera_to_world: ``(4, 4)`` pose (OpenCV axes).
    """
    labels = np.zeros(depth.shape, np.uint8)
    rows, cols = np.nonzero(segments > 0)
    if rows.size == 0:
        return labels
    d = depth[rows, cols].astype(float)
    cam = np.stack([(cols - K[0, 2]) / K[0, 0] * d, (rows - K[1, 2]) / K[1, 1] * d, d], 1)
    world = cam @ camera_to_world[:3, :3].T + camera_to_world[:3, 3]
    positions, rotations = scene.pose
    segment = segments[rows, cols] - 1
    joint = scene.part_bodies[segment]
    local = np.einsum("nji,nj->ni", rotations[joint], world - positions[joint])  # R^T (p - x)
    rest = scene.body.skeleton.rest_positions()
    labels[rows, cols] = rest_parts(scene.body, local + rest[joint], segment)
    return labels

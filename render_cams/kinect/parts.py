"""The body-part set of the Kinect tracker: one part around each body17 joint.

Shotton et al. (CVPR 2011, section 2.2) paint 31 parts on their synthetic bodies, some
"defined to directly localise particular skeletal joints of interest" (elbow, wrist, knee,
ankle...), others to fill the space between them; a joint proposal is the mode of its part's
pixels pushed into the body (their section 4). This set keeps only the joint-localising kind:
part ``k + 1`` is the surface around body17 joint ``k`` (:data:`PART_NAMES`), and 0 is no
body. 17 parts instead of 31 because every joint the tracker reports is built from the body17
joints (:mod:`.rig_joints`), so a part between two joints would only be a class to tell apart,
with fewer training pixels per class, that yields no proposal.

Each vertex of the render body takes the part of the nearest (rest pose) body17 joint among
those its segment may touch (:data:`CANDIDATES`: a forearm vertex belongs to the elbow or the
wrist, never to the hip it passes in an arms-down rest pose), so parts are painted on the
surface and move with it, as in Shotton's renders.
"""

from __future__ import annotations

import numpy as np

from avatar_models.body import BodyDescription
from avatar_models.body17 import BODY17, INDEX
from avatar_models.rigs import identify_rig
from render_cams.scene import BodyScene

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


def vertex_parts(body: BodyDescription, vertices: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """``(V,)`` uint8 part labels (1..17) of render-body vertices.

    Args:
        vertices: ``(V, 3)`` positions in the frame of each vertex's segment body.
        segment: ``(V,)`` index into ``body.segments`` of each vertex.
    """
    skeleton = body.skeleton
    rest = skeleton.rest_positions()
    b17_rest = rest[identify_rig(skeleton).body17_indices(skeleton)]  # (17, 3)
    bodies = np.array([s.body for s in body.segments])
    world = vertices + rest[bodies[segment]]  # rest rotations are the identity
    labels = np.empty(len(vertices), np.uint8)
    for k, seg in enumerate(body.segments):
        mine = segment == k
        allowed = segment_candidates(seg.kind, seg.side)
        dist = np.linalg.norm(world[mine, None] - b17_rest[allowed], axis=-1)
        labels[mine] = allowed[np.argmin(dist, axis=1)] + 1
    return labels


def paint_parts(scene: BodyScene) -> None:
    """Paint ``scene``'s body with these parts (:meth:`BodyScene.paint`)."""
    scene.paint(vertex_parts(scene.body, scene.body_frame_vertices, scene.vertex_segments))

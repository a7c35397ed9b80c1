"""Sizing the humanoid to a source motion for retargeting (:func:`humanoid_body`).

Sizing (the choice we made): by default the *humanoid is sized to the source*. The avatar rig
is rebuilt with one length factor per segment kind (thigh, shank, foot, upper arm, forearm,
torso, head) so that its body17 distances equal the source's medians over the clip, with
shoulders and hips placed where the source has them relative to neck and pelvis
(:func:`fitted_body`). The targets are then the source's body17 positions unchanged, so the
residual measures what the rigs cannot share (spine curvature, joint ranges), not a size
mismatch. When a body is given, the *targets are scaled* instead, uniformly about the world
origin by the ratio of both skeletons' standing heights
(:func:`avatar_models.measure.standing_height`), so stride length scales with the body.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import BodyDescription, build_body
from avatarsim.avatar_models.body.anatomy import classify
from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import body17_positions, load_rig

TEMPLATE_RIG = "avatar"
SEGMENT_SPANS: dict[str, tuple[tuple[str, str], ...]] = {
    "thigh": (("l_hip", "l_knee"), ("r_hip", "r_knee")),
    "shank": (("l_knee", "l_ankle"), ("r_knee", "r_ankle")),
    "foot": (("l_ankle", "l_foot"), ("r_ankle", "r_foot")),
    "upper_arm": (("l_shoulder", "l_elbow"), ("r_shoulder", "r_elbow")),
    "forearm": (("l_elbow", "l_wrist"), ("r_elbow", "r_wrist")),
    "torso": (("pelvis", "neck"),),
    "head": (("neck", "head"),),
}
"""Segment kind -> the body17 distances its length factor sets (sides averaged). In the
avatar rig each of these distances runs through bones of that one kind only, so one factor
per kind matches them exactly in the rest pose."""


def span_lengths(positions: np.ndarray) -> dict[str, float]:
    """Median over frames of each :data:`SEGMENT_SPANS` distance in body17 ``positions
    (T, 17, 3)``, averaged over the sides."""
    out = {}
    for kind, spans in SEGMENT_SPANS.items():
        a = positions[:, [INDEX[s[0]] for s in spans]]
        b = positions[:, [INDEX[s[1]] for s in spans]]
        out[kind] = float(np.median(np.linalg.norm(a - b, axis=-1), axis=0).mean())
    return out


GIRDLES: dict[str, tuple[str, str]] = {
    "neck": ("l_shoulder", "r_shoulder"),
    "pelvis": ("l_hip", "r_hip"),
}
"""Anchor -> the pair of joints hung from it whose rest placement is copied from the source."""


def trunk_offsets(positions: np.ndarray, anchor: str) -> np.ndarray:
    """``(2, 3)`` median position of the :data:`GIRDLES` pair of ``anchor`` relative to the
    anchor in body17 ``positions (T, 17, 3)``, in a trunk frame (up: pelvis to neck; left:
    from the right to the left joint of the pair, made orthogonal to up; forward: left x up).
    In a rest pose standing upright this frame is the world frame."""
    pair = GIRDLES[anchor]
    p = {n: positions[:, INDEX[n]] for n in ("pelvis", "neck", anchor, *pair)}
    up = p["neck"] - p["pelvis"]
    up /= np.linalg.norm(up, axis=-1, keepdims=True)
    left = p[pair[0]] - p[pair[1]]
    left -= np.sum(left * up, axis=-1, keepdims=True) * up
    left /= np.linalg.norm(left, axis=-1, keepdims=True)
    frame = np.stack([np.cross(left, up), left, up], axis=1)  # (T, 3 axes, 3)
    rel = np.stack([p[pair[0]], p[pair[1]]], axis=1) - p[anchor][:, None]
    return np.median(np.einsum("tab,tkb->tka", frame, rel), axis=0)


def fitted_body(motion: Motion, mass_kg: float = 75.0) -> BodyDescription:
    """The avatar-rig humanoid with each segment kind scaled to ``motion``'s body17
    distances, shoulders and hips placed as the source's (:func:`trunk_offsets`)."""
    rig = load_rig(TEMPLATE_RIG)
    sk = rig.skeleton
    b17 = rig.body17_indices(sk)
    rest = sk.rest_positions()[b17]
    source = body17_positions(motion)
    ours, theirs = span_lengths(rest[None]), span_lengths(source)
    scale = {kind: theirs[kind] / ours[kind] for kind in SEGMENT_SPANS}
    rig_kinds = classify(sk, rig).bone_kind
    # Shoulders and hips: place each where the source has it relative to the neck or the
    # pelvis (the avatar's clavicles are bones of kind "torso", so no length factor alone
    # can set shoulder width and height). Offsets are set before the kind factors apply,
    # hence the division; the bones between anchor and joint are of that joint's kind.
    offsets = sk.offsets.copy()
    rest_all = sk.rest_positions()
    for anchor, pair in GIRDLES.items():
        at = rest_all[int(b17[INDEX[anchor]])]
        for name, rel in zip(pair, trunk_offsets(source, anchor), strict=True):
            j = int(b17[INDEX[name]])
            factor = scale.get(rig_kinds[j], 1.0)
            offsets[j] = rel / factor - (rest_all[sk.parents[j]] - at)
    return build_body(sk.with_offsets(offsets), mass_kg=mass_kg, segment_scale=scale)


def humanoid_body(motion: Motion, mass_kg: float = 75.0) -> BodyDescription:
    """The body a foreign-rig ``motion`` is retargeted onto: the one that the skeleton of
    :func:`fitted_body` builds (``build_body(result.motion.skeleton)``, what a caller
    simulates). fitted_body's own segment scaling also sizes geoms (toe box 1 cm shorter,
    head, masses), and a reference made for other feet than the simulated ones puts the toes
    into the floor."""
    return build_body(fitted_body(motion).skeleton, mass_kg=mass_kg)

"""Kinect rig joints placed on any :class:`~avatar_models.Motion` (no noise, no tracking; the
oracle skeleton's), or on a tracker's body17 joints (:func:`rig_joints_from_body17`).

Joints on a Kinect rig (``kinect_v2``: 25, ``azure_kinect``: 32) come from the motion's body17
joints: mapped joints are the body17 positions themselves; spine levels lie on the pelvis-neck
line at the rig's rest fractions; other joints (hands, hand tips, thumbs, clavicles, nose, eyes,
ears) keep their rest offset from an anchor joint, scaled by the subject's segment length and
turned with the anchor (the motion's own wrist/head rotation, or the torso frame of body17).

Orientations of the oracle (world, wxyz, relative to the rig's T-pose; a tracker's come
from :mod:`.orientations`): Kinect V2 has no bone roll, so each
joint's orientation is the shortest rotation taking its rest bone (parent -> joint) to the
current one (MoveBox paper, section IV-A1). Azure Kinect reports full orientations: the
anchor's rotation (the motion's joint rotation aligned to the rig's rest bone, or the torso
frame).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion, quat
from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.rigs import Rig, identify_rig

# body17 joint -> the body17 segment (from, to) that sets its direction and length scale.
_REFERENCE_SEGMENT = {
    "pelvis": ("pelvis", "neck"),
    "neck": ("pelvis", "neck"),
    "head": ("neck", "head"),
    **{f"{s}_shoulder": (f"{s}_shoulder", f"{s}_elbow") for s in "lr"},
    **{f"{s}_elbow": (f"{s}_elbow", f"{s}_wrist") for s in "lr"},
    **{f"{s}_wrist": (f"{s}_elbow", f"{s}_wrist") for s in "lr"},
    **{f"{s}_hip": (f"{s}_hip", f"{s}_knee") for s in "lr"},
    **{f"{s}_knee": (f"{s}_knee", f"{s}_ankle") for s in "lr"},
    **{f"{s}_ankle": (f"{s}_ankle", f"{s}_foot") for s in "lr"},
    **{f"{s}_foot": (f"{s}_ankle", f"{s}_foot") for s in "lr"},
}
# Joints anchored in the torso frame rather than by the motion's own joint rotation.
_TORSO_ANCHORS = ("pelvis", "neck")

# Anchor (body17) of every joint that is neither mapped nor on the pelvis-neck line.
EXTRA_ANCHORS: dict[str, dict[str, str]] = {
    "kinect_v2": {
        **{
            f"{j}{side}": f"{s}_wrist"
            for j in ("Hand", "HandTip", "Thumb")
            for s, side in (("l", "Left"), ("r", "Right"))
        },
    },
    "azure_kinect": {
        **{
            f"{j}_{side}": f"{s}_wrist"
            for j in ("HAND", "HANDTIP", "THUMB")
            for s, side in (("l", "LEFT"), ("r", "RIGHT"))
        },
        "CLAVICLE_LEFT": "neck",
        "CLAVICLE_RIGHT": "neck",
        **{j: "head" for j in ("NOSE", "EYE_LEFT", "EYE_RIGHT", "EAR_LEFT", "EAR_RIGHT")},
    },
}


def rig_joints(motion: Motion, rig: Rig) -> tuple[np.ndarray, np.ndarray]:
    """``(T, J, 3)`` positions and ``(T, J, 4)`` orientations of ``rig``'s joints placed on
    ``motion`` (see the module docstring); no noise."""
    source = identify_rig(motion.skeleton)
    src_pos, src_rot = motion.fk()
    b17 = src_pos[:, source.body17_indices(motion.skeleton)]
    src_b17_rot = src_rot[:, source.body17_indices(motion.skeleton)]
    rest_src = _rest_positions(motion.skeleton)[source.body17_indices(motion.skeleton)]
    rig_rest = _rest_positions(rig.skeleton)
    rig_b17 = rig_rest[rig.body17_indices()]

    torso = _torso_frames(b17)
    torso_rest_rig = _torso_frames(rig_b17[None])[0]
    names = rig.skeleton.names
    n_frames = motion.n_frames
    positions = np.empty((n_frames, len(names), 3))
    anchor_rot = np.empty((n_frames, len(names), 3, 3))
    joint_of_b17 = {v: k for k, v in rig.body17.items()}
    spine = _spine_fractions(rig)
    extras = EXTRA_ANCHORS[rig.name]
    for j, name in enumerate(names):
        if name in joint_of_b17:
            b = joint_of_b17[name]
            positions[:, j] = b17[:, INDEX[b]]
            anchor_rot[:, j] = _anchor_rotation(b, src_b17_rot, torso, rest_src, rig_b17)
        elif name in spine:
            f = spine[name]
            positions[:, j] = (1 - f) * b17[:, INDEX["pelvis"]] + f * b17[:, INDEX["neck"]]
            anchor_rot[:, j] = torso @ torso_rest_rig.T
        else:
            b = extras[name]
            rot = _anchor_rotation(b, src_b17_rot, torso, rest_src, rig_b17)
            if b in _TORSO_ANCHORS:
                rot = torso @ torso_rest_rig.T
            a0, a1 = (INDEX[x] for x in _REFERENCE_SEGMENT[b])
            scale = np.linalg.norm(rest_src[a1] - rest_src[a0]) / np.linalg.norm(
                rig_b17[a1] - rig_b17[a0]
            )
            offset = (rig_rest[j] - rig_b17[INDEX[b]]) * scale
            positions[:, j] = b17[:, INDEX[b]] + rot @ offset
            anchor_rot[:, j] = rot
    if rig.name == "kinect_v2":
        return positions, _swing_orientations(positions, rig_rest, rig.skeleton.parents)
    return positions, quat.from_matrix(anchor_rot)


def _anchor_rotation(b17: str, src_rot, torso, rest_src, rig_b17) -> np.ndarray:
    """``(T, 3, 3)`` rotation of body17 joint ``b17`` relative to the rig's rest pose: the
    motion's joint rotation composed with the rest alignment of its reference segment (torso
    frame for pelvis and neck)."""
    if b17 in _TORSO_ANCHORS:
        return torso @ _torso_frames(rig_b17[None])[0].T
    a0, a1 = (INDEX[x] for x in _REFERENCE_SEGMENT[b17])
    align = _shortest_rotation(rig_b17[a1] - rig_b17[a0], rest_src[a1] - rest_src[a0])
    return src_rot[:, INDEX[b17]] @ align


def _rest_positions(skeleton) -> np.ndarray:
    """``(J, 3)`` world joint positions of the rest pose (identity rotations)."""
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (1, skeleton.n_joints, 1))
    return Motion(skeleton, 1.0, skeleton.offsets[:1], identity).global_positions()[0]


def _spine_fractions(rig: Rig) -> dict[str, float]:
    """Joints strictly between the rig's pelvis and neck joints -> fraction of the way up."""
    sk = rig.skeleton
    pelvis, neck = sk.index(rig.body17["pelvis"]), sk.index(rig.body17["neck"])
    chain = sk.chain(neck)
    chain = chain[chain.index(pelvis) :]
    lengths = np.cumsum(sk.bone_lengths[chain[1:]])
    return {
        sk.names[j]: float(c / lengths[-1]) for j, c in zip(chain[1:-1], lengths[:-1], strict=True)
    }


def _torso_frames(b17: np.ndarray) -> np.ndarray:
    """``(T, 3, 3)`` torso frames from body17 positions ``(T, 17, 3)``: z pelvis -> neck, y
    towards the left hip (orthogonalised), x = y x z (forward; identity in the rest pose)."""
    z = b17[:, INDEX["neck"]] - b17[:, INDEX["pelvis"]]
    z /= np.linalg.norm(z, axis=-1, keepdims=True)
    y = b17[:, INDEX["l_hip"]] - b17[:, INDEX["r_hip"]]
    y -= np.sum(y * z, -1, keepdims=True) * z
    y /= np.linalg.norm(y, axis=-1, keepdims=True)
    return np.stack([np.cross(y, z), y, z], axis=-1)


def _shortest_rotation(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` smallest rotation taking direction ``u`` to ``v`` (Rodrigues); a half
    turn about an axis perpendicular to ``u`` when they are opposite; NaN where ``u`` or
    ``v`` is not finite (a joint a tracker did not find)."""
    u, v = np.broadcast_arrays(u, v)
    lost = ~np.all(np.isfinite(u) & np.isfinite(v), axis=-1)
    u = np.where(lost[..., None], [1.0, 0.0, 0.0], u)
    v = np.where(lost[..., None], [1.0, 0.0, 0.0], v)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    axis = np.cross(u, v)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(u * v, -1)
    fallback = np.cross(u, np.where(np.abs(u[..., :1]) < 0.9, [1.0, 0, 0], [0, 1.0, 0]))
    axis = np.where((sin < 1e-9)[..., None], fallback, axis)
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = np.arctan2(sin, cos)
    return np.where(
        lost[..., None, None], np.nan, quat.to_matrix(quat.from_axis_angle(axis, angle))
    )


def _swing_orientations(positions: np.ndarray, rest: np.ndarray, parents) -> np.ndarray:
    """``(T, J, 4)`` roll-free orientations: each joint's rest bone (parent -> joint; root ->
    its first child) swung onto the current bone."""
    parents = np.asarray(parents)
    first_child = int(np.flatnonzero(parents == 0)[0])
    start = np.where(parents < 0, 0, parents)
    end = np.arange(len(parents))
    end[0] = first_child
    rest_bones = rest[end] - rest[start]
    bones = positions[:, end] - positions[:, start]
    swing = _shortest_rotation(np.broadcast_to(rest_bones, bones.shape), bones)
    lost = np.isnan(swing[..., 0, 0])
    swing[lost] = np.eye(3)
    return np.where(lost[..., None], np.nan, quat.from_matrix(swing))


def rig_joints_from_body17(b17: np.ndarray, rig: Rig) -> np.ndarray:
    """``(T, J, 3)`` positions of ``rig``'s joints from measured body17 positions
    ``(T, 17, 3)`` alone (a tracker's output; NaN where a joint was not found, and NaN in
    every joint built from it); their orientations are :mod:`.orientations`'.

    Mapped joints are the body17 points, spine levels lie on the pelvis-neck line, and every
    other joint keeps its rest offset from its anchor, scaled by the take's median length of
    the anchor's reference segment and swung with that segment (torso frame for torso
    anchors)."""
    rig_rest = _rest_positions(rig.skeleton)
    rig_b17 = rig_rest[rig.body17_indices()]
    names = rig.skeleton.names
    joint_of_b17 = {v: k for k, v in rig.body17.items()}
    spine = _spine_fractions(rig)
    extras = EXTRA_ANCHORS[rig.name]
    torso = _torso_frames(b17) @ _torso_frames(rig_b17[None])[0].T
    positions = np.empty((b17.shape[0], len(names), 3))
    for j, name in enumerate(names):
        if name in joint_of_b17:
            positions[:, j] = b17[:, INDEX[joint_of_b17[name]]]
        elif name in spine:
            f = spine[name]
            positions[:, j] = (1 - f) * b17[:, INDEX["pelvis"]] + f * b17[:, INDEX["neck"]]
        else:
            b = extras[name]
            a0, a1 = (INDEX[x] for x in _REFERENCE_SEGMENT[b])
            rest_bone = rig_b17[a1] - rig_b17[a0]
            bone = b17[:, a1] - b17[:, a0]
            lengths = np.linalg.norm(bone, axis=-1)
            lengths = lengths[np.isfinite(lengths)]  # none: the segment was never found
            scale = (np.median(lengths) if lengths.size else np.nan) / np.linalg.norm(rest_bone)
            rot = torso if b in _TORSO_ANCHORS else _shortest_rotation(rest_bone, bone)
            offset = (rig_rest[j] - rig_b17[INDEX[b]]) * scale
            positions[:, j] = b17[:, INDEX[b]] + rot @ offset
    return positions


def body17_dependencies(rig: Rig) -> list[np.ndarray]:
    """Per rig joint, the body17 indices :func:`rig_joints_from_body17` builds it from."""
    joint_of_b17 = {v: k for k, v in rig.body17.items()}
    spine = _spine_fractions(rig)
    out = []
    for name in rig.skeleton.names:
        if name in joint_of_b17:
            out.append(np.array([INDEX[joint_of_b17[name]]]))
        elif name in spine:
            out.append(np.array([INDEX["pelvis"], INDEX["neck"]]))
        else:
            b = EXTRA_ANCHORS[rig.name][name]
            out.append(np.array(sorted({INDEX[b], *(INDEX[x] for x in _REFERENCE_SEGMENT[b])})))
    return out

"""Animation masks: layers per bone set, composed (MoveBox §III-B3: "a body animation and an
independent lip sync animation can both be applied to the same avatar").

A :class:`Layer` is a motion on the avatar rig and the bones it owns; :func:`compose` starts
from a base motion and, layer by layer, replaces (or, with a weight below 1, blends towards)
the local rotations of the layer's bones only. Bones outside every layer keep the base's
rotations bit for bit; the root position comes from the last layer that owns the root.

Bone sets of the avatar rig (:func:`bone_set`): ``face`` (jaw and eyelids), ``body``
(everything else), ``upper_body`` (the spine and all above it, face excluded) and
``lower_body`` (root, pelvis and legs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Motion, Skeleton
from avatarsim.synthesis.base import SynthesisError

FACE_PARTS = ("Jaw", "Eyelid")
UPPER_ROOT = "Bip01 Spine"
BONE_SETS = ("body", "upper_body", "lower_body", "face")


def _descendants(skeleton: Skeleton, root: int) -> np.ndarray:
    """``(J,)`` bool: ``root`` and every joint below it."""
    inside = np.zeros(skeleton.n_joints, bool)
    inside[root] = True
    for j in range(root + 1, skeleton.n_joints):  # parents come before children
        inside[j] = inside[skeleton.parents[j]]
    return inside


def bone_set(skeleton: Skeleton, name: str) -> np.ndarray:
    """``(J,)`` bool mask of the bone set ``name`` (module docstring) on an avatar skeleton.

    Raises:
        SynthesisError: an unknown set, or a skeleton without the avatar's joints.
    """
    if name not in BONE_SETS:
        raise SynthesisError(f"unknown bone set {name!r}; known: {', '.join(BONE_SETS)}")
    if UPPER_ROOT not in skeleton:
        raise SynthesisError(f"bone sets are defined on the avatar rig, not {skeleton!r}")
    face = np.array([any(p in n for p in FACE_PARTS) for n in skeleton.names])
    upper = _descendants(skeleton, skeleton.index(UPPER_ROOT)) & ~face
    return {"face": face, "body": ~face, "upper_body": upper, "lower_body": ~face & ~upper}[name]


@dataclass(frozen=True, eq=False)
class Layer:
    """A motion and the bones it drives.

    Attributes:
        motion: on the same skeleton layout and fps as the base.
        bones: a bone-set name or a ``(J,)`` bool mask.
        weight: 1 replaces the base's rotations, less blends towards them (nlerp).
    """

    motion: Motion
    bones: str | np.ndarray
    weight: float = 1.0


def compose(base: Motion, layers: list[Layer]) -> Motion:
    """``base`` with each layer applied in order over the frames both have (module docstring).

    Raises:
        SynthesisError: a layer on another skeleton layout or fps, or a weight outside [0, 1].
    """
    root = base.root_pos.copy()
    rot = base.local_rot.copy()
    for layer in layers:
        m = layer.motion
        if not m.skeleton.same_topology(base.skeleton) or abs(m.fps - base.fps) > 1e-9:
            raise SynthesisError(
                f"a layer on {m.skeleton!r} at {m.fps:g} fps cannot mask a base on "
                f"{base.skeleton!r} at {base.fps:g} fps"
            )
        if not 0.0 <= layer.weight <= 1.0:
            raise SynthesisError(f"a layer weight must be in [0, 1], got {layer.weight}")
        mask = (
            layer.bones
            if isinstance(layer.bones, np.ndarray)
            else bone_set(m.skeleton, layer.bones)
        )
        n = min(m.n_frames, base.n_frames)
        mine = m.local_rot[:n][:, mask]
        if layer.weight < 1.0:
            theirs = rot[:n][:, mask]
            sign = np.where(np.sum(theirs * mine, -1, keepdims=True) < 0, -1.0, 1.0)
            mine = (1 - layer.weight) * theirs + layer.weight * sign * mine
            mine /= np.linalg.norm(mine, axis=-1, keepdims=True)
        rot[:n, mask] = mine
        if mask[0]:
            root[:n] = (1 - layer.weight) * root[:n] + layer.weight * m.root_pos[:n]
    return base.replace(root_pos=root, local_rot=rot)

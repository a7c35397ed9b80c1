"""Joint orientations from tracked joint positions, as each Kinect derives them.

Every joint's frame has its Y axis along its bone (parent -> joint; the root: root -> its
first child), the Y convention of the Kinect SDKs' ``JointOrientation``; Z is a roll
reference made perpendicular to the bone and X = Y x Z. An orientation is reported as world
wxyz relative to the rig's T-pose: ``F_t @ F_rest^T``, with ``F_rest`` built the same way on
the rig's rest positions. The two sensors differ in their roll reference:

- Kinect V2 (:func:`v2_orientations`) has only positions to go on: the roll of a joint is
  the plane of its bone and its child's bone (the normal ``bone x child``), and where the
  two are within :data:`STRAIGHT_RAD` of a line (a straight limb, a leaf joint, the spine
  levels on the pelvis-neck line) the body's forward (left hip -> right hip x pelvis ->
  neck). A limb that straightens therefore turns its roll by itself, and a nearly straight
  one flips with the tracker's noise: the unstable roll of MoveBox §IV-B1.
- Azure Kinect (:func:`azure_orientations`) reports full, stable orientations from its
  32-joint rig (MoveBox §IV-A2): the body's forward for the trunk and limbs, the thumb
  (wrist -> thumb) for the wrist, hand and hand-tip joints, the nose (head -> nose) for the
  head, eyes and ears.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.rigs import Rig

STRAIGHT_RAD = np.radians(10.0)
"""Below this angle between a V2 bone and its child's bone the plane of the two is taken as
undefined and the body's forward sets the roll (a choice: the SDK does not publish one)."""

_AZURE_ROLL_FROM = {
    **{
        f"{j}_{side}": (f"WRIST_{side}", f"THUMB_{side}")
        for j in ("WRIST", "HAND", "HANDTIP")
        for side in ("LEFT", "RIGHT")
    },
    **{j: ("HEAD", "NOSE") for j in ("HEAD", "EYE_LEFT", "EYE_RIGHT", "EAR_LEFT", "EAR_RIGHT")},
}
"""Azure joints whose roll reference is a direction between two of its 32 joints."""


def tracked_orientations(positions: np.ndarray, rig: Rig) -> np.ndarray:
    """``(T, J, 4)`` orientations of ``rig``'s joints from their positions ``(T, J, 3)``
    (NaN where a joint they need is NaN), the way ``rig``'s sensor derives them."""
    if rig.name == "kinect_v2":
        return v2_orientations(positions, rig)
    if rig.name == "azure_kinect":
        return azure_orientations(positions, rig)
    raise ValueError(f"no Kinect derives orientations for the {rig.name!r} rig")


def v2_orientations(positions: np.ndarray, rig: Rig) -> np.ndarray:
    """Kinect V2 (module docstring): roll from the plane of each bone and its child's."""

    def roll(p: np.ndarray) -> np.ndarray:
        bones, children = _bones(p, rig), _child_bones(p, rig)
        normal = np.cross(bones, children)
        with np.errstate(invalid="ignore", divide="ignore"):  # a leaf, a lost joint: straight
            sin = np.linalg.norm(normal, axis=-1) / (
                np.linalg.norm(bones, axis=-1) * np.linalg.norm(children, axis=-1)
            )
            bent = np.nan_to_num(sin, nan=0.0, posinf=0.0) > np.sin(STRAIGHT_RAD)
        return np.where(bent[..., None], normal, _forward(p, rig)[..., None, :])

    return _relative_to_rest(positions, rig, roll)


def azure_orientations(positions: np.ndarray, rig: Rig) -> np.ndarray:
    """Azure Kinect (module docstring): roll from the body's forward, the thumbs and nose."""
    names = rig.skeleton.names

    def roll(p: np.ndarray) -> np.ndarray:
        ref = np.repeat(_forward(p, rig)[..., None, :], len(names), axis=-2)
        for name, (a, b) in _AZURE_ROLL_FROM.items():
            ref[..., names.index(name), :] = p[..., names.index(b), :] - p[..., names.index(a), :]
        return ref

    return _relative_to_rest(positions, rig, roll)


def _relative_to_rest(positions: np.ndarray, rig: Rig, roll) -> np.ndarray:
    """``(T, J, 4)`` ``F_t @ F_rest^T`` of the frames from bones and ``roll(p) (..., J, 3)``."""
    rest = rig.skeleton.rest_positions()[None]
    frames = _frames(_bones(positions, rig), roll(positions))
    rest_frames = _frames(_bones(rest, rig), roll(rest))
    rot = frames @ np.swapaxes(rest_frames, -1, -2)
    lost = ~np.all(np.isfinite(rot), axis=(-2, -1))
    rot[lost] = np.eye(3)
    return np.where(lost[..., None], np.nan, quat.from_matrix(rot))


def _frames(bones: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` frames (columns X, Y, Z): Y along ``bones``, Z the part of ``ref``
    perpendicular to it (world up, then world X, where ``ref`` is along the bone)."""
    y = bones / np.linalg.norm(bones, axis=-1, keepdims=True)
    z = ref
    for fallback in ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]):
        z = z - np.sum(z * y, -1, keepdims=True) * y
        norm = np.linalg.norm(z, axis=-1, keepdims=True)
        z = np.where(norm > 1e-6, z, np.asarray(fallback))
    z = z - np.sum(z * y, -1, keepdims=True) * y
    z = z / np.linalg.norm(z, axis=-1, keepdims=True)
    return np.stack([np.cross(y, z), y, z], axis=-1)


def _bones(p: np.ndarray, rig: Rig) -> np.ndarray:
    """``(..., J, 3)`` parent -> joint (the root: root -> its first child)."""
    parents = np.asarray(rig.skeleton.parents)
    start = np.where(parents < 0, 0, parents)
    end = np.arange(len(parents))
    end[0] = int(np.flatnonzero(parents == 0)[0])
    return p[..., end, :] - p[..., start, :]


def _child_bones(p: np.ndarray, rig: Rig) -> np.ndarray:
    """``(..., J, 3)`` joint -> its first child (zero for a leaf)."""
    parents = np.asarray(rig.skeleton.parents)
    child = np.arange(len(parents))
    for j in range(len(parents) - 1, 0, -1):  # the lowest-index child wins
        child[parents[j]] = j
    return p[..., child, :] - p[..., np.arange(len(parents)), :]


def _forward(p: np.ndarray, rig: Rig) -> np.ndarray:
    """``(..., 3)`` the body's forward: (left hip - right hip) x (pelvis -> neck)."""
    sk, b17 = rig.skeleton, rig.body17
    at = {k: p[..., sk.index(b17[k]), :] for k in ("l_hip", "r_hip", "pelvis", "neck")}
    return np.cross(at["l_hip"] - at["r_hip"], at["neck"] - at["pelvis"])

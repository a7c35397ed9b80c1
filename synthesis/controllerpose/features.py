"""The network's input, as ControllerPose §4.3 builds it, and its training targets.

Per skeleton (a 2D body17 detection in one view): the unit direction vectors between all
136 pairs of the 17 keypoints (2D, so 272 numbers) and the 17 joint confidences: 289
features (:data:`PER_SKELETON`). A direction that touches an undetected joint (confidence
0) is 0; the confidences say which ones those are.

Up to four skeletons per frame (:data:`SKELETON_SLOTS`): the paper's left and right streams,
each in its composite and its torso-normal view, in that order (the dataset's
``fisheye_view_uv``: left composite, left torso, right composite, right torso). A slot
whose view shows fewer than :data:`MIN_JOINTS` joints holds no skeleton: it is masked
(``found`` False, its features 0);
a frame with no skeleton is dropped from training and held over by the synthesiser, as the
paper's pipeline "awaits better frames".

The 15 VR features (§4.3): headset height, and each controller's X/Y/Z position and
X/Y/Z/W quaternion with respect to the head. "With respect to the head" is read as in the
head's heading frame (yaw only, origin at the head): the skeletons give no world heading,
so neither do the VR features, and the pose targets are expressed in that frame too
(:func:`heading_targets`). Quaternions are stored wxyz with w >= 0 (one hemisphere).

"Multi-input" (§4.3, Fig. 6I) is read as one input branch per skeleton slot plus one for the
VR features, joined into one trunk (:mod:`.network`); :data:`LAYOUT` names that layout, and
a checkpoint trained on another layout is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import AvatarsimError, quat
from avatarsim.avatar_models.body17_angles import (
    DOF_SLICES,
    ROOT,
    matrix_to_rotvec,
    rotvec_to_matrix,
)

N_KEYPOINTS = 17
PAIRS = np.triu_indices(N_KEYPOINTS, 1)
N_PAIRS = len(PAIRS[0])  # 136
PER_SKELETON = 2 * N_PAIRS + N_KEYPOINTS  # 289
SKELETON_SLOTS = 4
VR_FEATURES = 15
# Fewer detected joints than this is no skeleton (not from the paper: a view with a few
# joints at its edge is not a body detection).
MIN_JOINTS = 6
LAYOUT = {
    "version": 2,  # 1: the slots held the four cameras' skeletons
    "skeleton_slots": SKELETON_SLOTS,
    "per_skeleton": PER_SKELETON,
    "vr_features": VR_FEATURES,
    "skeleton": "136 unit 2D directions (pairs i<j of body17) + 17 confidences",
    "slots": "left composite, left torso view, right composite, right torso view",
    "vr": "headset height; left, right controller: position (3) + quaternion wxyz (4) "
    "in the head's heading frame",
}


class FeatureError(AvatarsimError, ValueError):
    """Features that cannot go into the network (NaN, wrong shape, no keypoints)."""


@dataclass(frozen=True)
class Features:
    """The network's input for ``N`` frames.

    Attributes:
        skeletons: ``(N, 4, 289)`` float32, 0 where not found.
        found: ``(N, 4)`` bool.
        vr: ``(N, 15)`` float32.
    """

    skeletons: np.ndarray
    found: np.ndarray
    vr: np.ndarray

    def __len__(self) -> int:
        return self.found.shape[0]

    def take(self, index: np.ndarray) -> Features:
        return Features(self.skeletons[index], self.found[index], self.vr[index])

    def check_finite(self, what: str) -> None:
        """Raises :class:`FeatureError` naming ``what`` if any feature is not finite."""
        for name, values in (("skeleton", self.skeletons), ("VR", self.vr)):
            bad = ~np.isfinite(values)
            if bad.any():
                frame = int(np.argwhere(bad)[0][0])
                raise FeatureError(
                    f"{what}: {int(bad.sum())} non-finite {name} features (first at frame "
                    f"{frame}); check the keypoints and VR poses there (NaN never enters "
                    "the network)"
                )


def skeleton_features(uv: np.ndarray, conf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``uv (..., 17, 2)`` pixels and ``conf (..., 17)`` in [0, 1] -> features
    ``(..., 289)`` and ``found (...,)`` (module docstring)."""
    detected = conf > 0.0
    found = detected.sum(-1) >= MIN_JOINTS
    i, j = PAIRS
    delta = uv[..., j, :] - uv[..., i, :]
    norm = np.linalg.norm(delta, axis=-1, keepdims=True)
    usable = (detected[..., i] & detected[..., j])[..., None] & (norm > 1e-9)
    directions = np.where(usable, delta / np.where(usable, norm, 1.0), 0.0)
    feats = np.concatenate(
        [directions.reshape(directions.shape[:-2] + (2 * N_PAIRS,)), np.where(detected, conf, 0)],
        -1,
    )
    return np.where(found[..., None], feats, 0.0).astype(np.float32), found


def heading_quat(yaw: np.ndarray) -> np.ndarray:
    """``(...,)`` yaw -> ``(..., 4)`` wxyz rotations about +Z."""
    return np.stack([np.cos(yaw / 2), 0 * yaw, 0 * yaw, np.sin(yaw / 2)], -1)


def vr_features(
    head_pos: np.ndarray, head_quat: np.ndarray, hand_pos: np.ndarray, hand_quat: np.ndarray
) -> np.ndarray:
    """``head_pos (..., 3)``, ``head_quat (..., 4)``, ``hand_pos (..., 2, 3)`` and
    ``hand_quat (..., 2, 4)`` (left, right controller; world, wxyz) -> ``(..., 15)``."""
    inv_heading = quat.conj(heading_quat(quat.yaw(head_quat)))[..., None, :]
    rel_pos = quat.rotate(inv_heading, hand_pos - head_pos[..., None, :])
    rel_quat = quat.normalize(quat.mul(inv_heading, hand_quat))
    rel_quat = np.where(rel_quat[..., :1] < 0, -rel_quat, rel_quat)
    per_hand = np.concatenate([rel_pos, rel_quat], -1)
    flat = per_hand.reshape(per_hand.shape[:-2] + (14,))
    return np.concatenate([head_pos[..., 2:3], flat], -1).astype(np.float32)


def heading_matrix(yaw: np.ndarray) -> np.ndarray:
    """``(...,)`` yaw -> ``(..., 3, 3)`` rotations about +Z."""
    return rotvec_to_matrix(np.asarray(yaw)[..., None] * np.array([0.0, 0.0, 1.0]))


def heading_targets(angles: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """``angles (..., 43)`` of a world pose -> the same pose in the heading frame of
    ``yaw (...,)`` (only the root's 3 DoF change)."""
    out = np.array(angles, dtype=np.float64)
    root = DOF_SLICES[ROOT]
    turned = np.swapaxes(heading_matrix(yaw), -1, -2) @ rotvec_to_matrix(out[..., root])
    out[..., root] = matrix_to_rotvec(turned)
    return out


def latest_sample(
    times: np.ndarray, valid: np.ndarray, at: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """For each query time ``at (N,)``, the index of the latest valid sample with time <= it
    among ``times (T,)`` / ``valid (T,)`` (a live system cannot see the future), and whether
    there is one: ``index (N,)``, ``ok (N,)``."""
    last_valid = np.maximum.accumulate(np.where(valid, np.arange(len(times)), -1))
    upto = np.searchsorted(times, at + 1e-6, side="right") - 1
    index = np.where(upto >= 0, last_valid[np.maximum(upto, 0)], -1)
    return np.maximum(index, 0), index >= 0

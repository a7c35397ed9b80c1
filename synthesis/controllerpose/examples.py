"""Training and evaluation examples: one per camera frame where a skeleton was found.

:func:`recording_examples` turns one recording (ground-truth ``body17``, the controller
cameras' keypoints, the VR stream) into :class:`Examples`: the features of :mod:`.features`
with VR samples taken causally (the latest valid one at or before the camera frame), and the
targets in the head's heading frame: the 43 angles (:mod:`avatar_models.body17_angles`),
the bone lengths and the pelvis-relative keypoints.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body17_angles import angles_from_positions
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS
from avatarsim.synthesis.controllerpose.features import (
    FeatureError,
    Features,
    heading_matrix,
    heading_targets,
    latest_sample,
    skeleton_features,
    vr_features,
)


@dataclass(frozen=True)
class Examples:
    """``N`` examples.

    Attributes:
        features: the network's input.
        angles: ``(N, 43)`` target angles, heading frame.
        lengths: ``(N, 17)`` bone lengths (m).
        positions: ``(N, 17, 3)`` keypoints, pelvis at the origin, heading frame.
        height: ``(N,)`` the subject's standing height (m), for §5.3's normalisation.
        group: ``(N,)`` int, the recording each example comes from.
        time: ``(N,)`` the camera frame's time within its recording (s), so that another
            method's output can be sampled at the same frames.
    """

    features: Features
    angles: np.ndarray
    lengths: np.ndarray
    positions: np.ndarray
    height: np.ndarray
    group: np.ndarray
    time: np.ndarray

    def __len__(self) -> int:
        return len(self.group)

    def take(self, index: np.ndarray) -> Examples:
        return Examples(
            self.features.take(index),
            *(getattr(self, f.name)[index] for f in fields(self)[1:]),
        )


def concat(parts: Sequence[Examples]) -> Examples:
    """The examples of ``parts``, in order."""
    return Examples(
        Features(
            *(np.concatenate([getattr(p.features, f.name) for p in parts]) for f in
              fields(Features))
        ),
        *(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Examples)[1:]),
    )  # fmt: skip


@dataclass(frozen=True)
class VRStream:
    """A VR recording: ``time (Tv,)``, ``positions (Tv, D, 3)``, ``quaternions (Tv, D, 4)``
    wxyz, ``valid (Tv, D)``, ``devices`` (D names, :class:`~render_cams.TrackingStream`'s)."""

    time: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    valid: np.ndarray
    devices: tuple[str, ...]


def frame_features(
    uv: np.ndarray, conf: np.ndarray, frame_time: np.ndarray, vr: VRStream
) -> tuple[Features, np.ndarray, np.ndarray]:
    """The features of ``T`` camera frames: ``uv (T, 4, 17, 2)``, ``conf (T, 4, 17)`` at
    ``frame_time (T,)``, with ``vr``'s latest samples.

    Returns:
        the features, the headset's heading yaw ``(T,)`` and ``usable (T,)``: a skeleton was
        found and the headset and both controllers have a valid sample so far.

    Raises:
        FeatureError: the VR stream lacks the headset or a controller.
    """
    missing = [d for d in HEADSET_AND_CONTROLLERS if d not in vr.devices]
    if missing:
        raise FeatureError(f"the VR stream has no {missing} (it has {list(vr.devices)})")
    columns = [vr.devices.index(d) for d in HEADSET_AND_CONTROLLERS]
    picks = [latest_sample(vr.time, vr.valid[:, c], frame_time) for c in columns]
    index = np.stack([p[0] for p in picks], -1)  # (T, 3)
    vr_ok = np.stack([p[1] for p in picks], -1).all(-1)
    pos = vr.positions[index, columns].astype(np.float64)  # (T, 3, 3)
    rot = vr.quaternions[index, columns].astype(np.float64)
    skeletons, found = skeleton_features(uv.astype(np.float64), conf.astype(np.float64))
    vr_feats = vr_features(pos[:, 0], rot[:, 0], pos[:, 1:], rot[:, 1:])
    features = Features(skeletons, found, vr_feats)
    return features, quat.yaw(rot[:, 0]), found.any(-1) & vr_ok


def recording_examples(
    body17: np.ndarray,
    uv: np.ndarray,
    conf: np.ndarray,
    frame_time: np.ndarray,
    vr: VRStream,
    height: float,
    group: int,
) -> Examples:
    """The usable frames of one recording as examples (module docstring); ``body17
    (T, 17, 3)`` world keypoints at the camera frames."""
    features, yaw, usable = frame_features(uv, conf, frame_time, vr)
    angles, lengths = angles_from_positions(body17)
    targets = heading_targets(angles, yaw)
    centred = body17 - body17[:, 2:3]
    turned = np.einsum("tji,tkj->tki", heading_matrix(yaw), centred)
    keep = np.flatnonzero(usable)
    n = len(keep)
    if n and not np.isfinite(targets[keep]).all():
        raise FeatureError(f"recording {group}: non-finite ground truth angles")
    return Examples(
        features.take(keep),
        targets[keep].astype(np.float32),
        lengths[keep].astype(np.float32),
        turned[keep].astype(np.float32),
        np.full(n, height, dtype=np.float32),
        np.full(n, group, dtype=np.int64),
        np.asarray(frame_time, dtype=np.float64)[keep],
    )

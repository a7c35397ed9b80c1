"""Tracker-to-joint offsets: AvatarGo's exact ones (§3.3-3.4, eqs. 2-3) and the fixed baseline.

Both are a rigid pose of the joint in the tracker's frame, ``(q_off, p_off)``, so that at
run time (``K`` trackers, ``B`` frames)::

    R_t(J) = R_t(T) q_off,      p_t(J) = p_t(T) + R_t(T) p_off

:func:`exact_offsets` stores them at the walk-in T-pose (t = 0) from the tracker poses
``p0(T), R0(T)`` and the avatar's joint poses ``p0(J), R0(J)``:
``q_off = R0(T)^-1 R0(J)`` and ``p_off = R0(T)^-1 v0(TJ)`` with ``v0(TJ) = p0(J) - p0(T)``,
which is eq. 2 ``p_t(J) = p_t(T) + R_t(T) R0(T)^-1 v0(TJ)`` and eq. 3
``R_t(J) = R_t(T) R0(T)^-1 R0(J)`` with the constant part computed once. Because ``R0(T)``
enters, any strap rotation of a tracker cancels (§3.4).

:func:`fixed_offsets` is the baseline §3.3 argues against (Fig. 2): one constant offset per
tracker, the nominal placement of :mod:`render_cams.vr.placements`, whatever the user's
straps and whatever the avatar's legs: the root lands behind the user or too low, and legs
longer than the user's bend while shorter ones float.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.render_cams.vr import Attachment


@dataclass(frozen=True, eq=False)
class TrackerOffsets:
    """Joint poses in their trackers' frames.

    Attributes:
        position: ``(K, 3)`` ``p_off``, metres in the tracker frame.
        rotation: ``(K, 4)`` ``q_off``, wxyz.
    """

    position: np.ndarray
    rotation: np.ndarray

    def joint_poses(
        self, tracker_pos: np.ndarray, tracker_rot: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Joint positions ``(..., K, 3)`` and wxyz rotations ``(..., K, 4)`` for tracker
        poses ``tracker_pos (..., K, 3)``, unit ``tracker_rot (..., K, 4)`` (eqs. 2-3).
        The offset turned by a matrix product: a few numpy calls where
        :func:`~avatar_models.quat.rotate` takes ~20 (a per-tick hot path)."""
        turned = quat.unit_to_matrix(tracker_rot) @ self.position[..., None]
        return tracker_pos + turned[..., 0], quat.mul(tracker_rot, self.rotation)


def exact_offsets(
    tracker_pos0: np.ndarray,
    tracker_rot0: np.ndarray,
    joint_pos0: np.ndarray,
    joint_rot0: np.ndarray,
) -> TrackerOffsets:
    """The exact offsets of §3.3 from the walk-in T-pose: trackers ``p0(T) (K, 3)``,
    ``R0(T) (K, 4)`` and the avatar's joints ``p0(J) (K, 3)``, ``R0(J) (K, 4)``."""
    inverse = quat.conj(quat.normalize(tracker_rot0))
    v0 = np.asarray(joint_pos0, float) - tracker_pos0  # v0(TJ)
    return TrackerOffsets(quat.rotate(inverse, v0), quat.mul(inverse, joint_rot0))


def fixed_offsets(attachments: Sequence[Attachment], scale: float = 1.0) -> TrackerOffsets:
    """The baseline: the nominal device-on-joint ``attachments`` (``K``), their positions
    times ``scale`` (the avatar's), inverted into joint-in-tracker offsets."""
    rot = np.stack([a.rotation for a in attachments])
    pos = scale * np.stack([a.position for a in attachments])
    inverse = quat.conj(rot)
    return TrackerOffsets(-quat.rotate(inverse, pos), inverse)

"""NotTracked and Inferred joints (Kinect SDK ``TrackingState``), handled on the avatar's local
rotations, per bone, before smoothing.

The paper reports the behaviour, not a rule: "Kinect v2 may react to a joint occlusion by
generating an impossible pose, Azure Kinect tend to returns a feasible position" (§IV-B3).
We handle both the same way, and say which:

- Tracked: used as it is.
- Inferred (the SDK guessed the joint): **blended**: the bone's rotation is
  ``nlerp(last tracked, inferred, INFERRED_WEIGHT)``, so a guess moves the avatar only part of
  the way.
- NotTracked (no data): **held**: the bone keeps its last output rotation.
- Never seen since the session started: **fallback** to the avatar's rest rotation.

A bone's state is the worst state of the Kinect joints it reads. Shapes: ``N`` frames,
``J`` avatar joints; the carry holds the last tracked and last output rotation of each bone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.render_cams.kinect import TrackingState

INFERRED_WEIGHT = 0.5
"""Share of an Inferred estimate in the bone's rotation (our choice; the paper gives none)."""


def bone_states(states: np.ndarray, sources: list[tuple[int, ...]]) -> np.ndarray:
    """``(N, J)`` int8 state per avatar joint: the minimum over the Kinect joints it reads
    (``states (N, K)``); Tracked for undriven joints."""
    out = np.full((states.shape[0], len(sources)), TrackingState.TRACKED, np.int8)
    for j, src in enumerate(sources):
        if src:
            out[:, j] = states[:, list(src)].min(axis=1)
    return out


def forward_fill(values: np.ndarray, known: np.ndarray, carry: np.ndarray) -> np.ndarray:
    """``values (N, J, C)`` where ``known (N, J)``, else the last known value before it (from
    ``carry (J, C)`` before the first)."""
    n = values.shape[0]
    stacked = np.concatenate([carry[None], values], axis=0)
    mask = np.concatenate([np.ones((1, known.shape[1]), bool), known], axis=0)
    index = np.maximum.accumulate(np.where(mask, np.arange(n + 1)[:, None], 0), axis=0)
    return np.take_along_axis(stacked, index[..., None], axis=0)[1:]


@dataclass
class ConfidenceFilter:
    """The state of the rules above across calls (``J`` joints).

    Attributes:
        last_tracked: ``(J, 4)`` each bone's last Tracked local rotation (rest at first).
        last_output: ``(J, 4)`` each bone's last output local rotation.
    """

    last_tracked: np.ndarray
    last_output: np.ndarray

    @classmethod
    def at_rest(cls, n_joints: int) -> ConfidenceFilter:
        rest = np.tile(quat.IDENTITY, (n_joints, 1))
        return cls(rest.copy(), rest.copy())

    def __call__(self, local_rot: np.ndarray, states: np.ndarray) -> np.ndarray:
        """``(N, J, 4)`` local rotations after the rules, for raw ``local_rot (N, J, 4)``
        and bone ``states (N, J)``."""
        tracked = states == TrackingState.TRACKED
        inferred = states == TrackingState.INFERRED
        anchor = forward_fill(local_rot, tracked, self.last_tracked)
        sign = np.where(np.sum(anchor * local_rot, -1, keepdims=True) < 0, -1.0, 1.0)
        blended = (1 - INFERRED_WEIGHT) * anchor + INFERRED_WEIGHT * sign * local_rot
        blended /= np.linalg.norm(blended, axis=-1, keepdims=True)
        seen = np.where(inferred[..., None], blended, local_rot)
        out = forward_fill(seen, tracked | inferred, self.last_output)
        if out.shape[0]:
            self.last_tracked = anchor[-1]
            self.last_output = out[-1]
        return out

"""Temporal smoothing of the output pose by an exponentially weighted moving average.

CoolMoves §3.1.4: ``p_t = w_t p_t + (1 - w_t) p_{t-1}`` with ``w_t`` the global match weight
of frame ``t``. Poses are local rotations; each joint's quaternion is averaged linearly in the
hemisphere of the previous output and renormalised (nlerp, which for one step of a smoothing
filter differs from slerp by far less than the matches differ from each other). A weight of 1
returns the new pose exactly, 0 holds the previous one; joints with weight 0 are how a hand
without matches (or tracking) keeps its last pose.

What it buys: the filter trades jitter for lag. With our global match weights (median 0.6 on
built-in cross-subject boxing and running, so about 0.7 frames of lag) it halves the
frame-to-frame jitter of the joints (mean second difference 1.7 -> 0.9 cm) and costs about
0.2 cm of mean error. The paper's 13.2 -> 11.4 cm gain came from real mocap, whose matches
jump between performers far more than the generator's consistent ones.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat


def ewma_step(previous: np.ndarray, current: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """One EWMA step on rotations ``(J, 4)`` (or ``(..., J, 4)``), weights ``(J,)`` in [0, 1]."""
    weight = np.asarray(weight, float)[..., None]
    # The new rotation's weight, signed into the previous one's hemisphere (w * -1 is -w).
    signed = np.where(quat.dot(previous, current)[..., None] < 0, -weight, weight)
    mixed = signed * current + (1.0 - weight) * previous
    norm = np.sqrt(quat.dot(mixed, mixed))[..., None]  # np.linalg.norm's sum
    # Antipodal halfway points (norm 0) cannot happen after the sign flip; guard anyway.
    return np.where(norm > 1e-12, mixed / np.maximum(norm, 1e-12), previous)


def ewma(rotations: np.ndarray, weights: np.ndarray, initial: np.ndarray) -> np.ndarray:
    """The filter over a sequence: ``rotations (T, J, 4)``, ``weights (T, J)`` from ``initial``.

    A recursive filter: each output needs the previous one, so this loops over frames (on
    whole ``(J, 4)`` arrays) exactly as the streaming path does.
    """
    out = np.empty_like(rotations)
    state = initial
    for t in range(rotations.shape[0]):
        state = ewma_step(state, rotations[t], weights[t])
        out[t] = state
    return out

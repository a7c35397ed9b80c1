"""Joint comparison and loop trimming (MoveBox §III-A5 and §III-B2).

The similarity index of two body states (one rotation per joint) is the sum over joints of
the magnitude of the vector part of ``q_1j q_2j^-1``:
``S_i = sum_j sqrt(x_j^2 + y_j^2 + z_j^2)`` with ``(w_j, x_j, y_j, z_j) = q_1j q_2j^-1``. It is
0 for identical states and grows as they differ. For unit quaternions the scalar part of
``q_1 q_2^-1`` is the dot product ``q_1 . q_2``, so each term is ``sqrt(1 - (q_1 . q_2)^2)``
(``sin`` of half the angle between them), which is how :func:`similarity_matrix` computes
all pairs at once.

A loop is trimmed "at a pair of frames, one near the beginning and one near the end, with
similar body positions" (§III-B2): the pair with the smallest index.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.synthesis.base import SynthesisError

PAIR_BLOCK = 256
"""Rows of the pair matrix computed at once (bounds memory to ``256 x M x J`` floats)."""


def similarity_index(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """``(...)`` S_i of body states ``q1, q2 (..., J, 4)`` (the paper's formula, literally)."""
    product = quat.mul(q1, quat.conj(q2))
    return np.linalg.norm(product[..., 1:], axis=-1).sum(axis=-1)


def similarity_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N, M)`` S_i of every pair of frames of ``a (N, J, 4)`` and ``b (M, J, 4)``."""
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    out = np.empty((a.shape[0], b.shape[0]))
    for start in range(0, a.shape[0], PAIR_BLOCK):  # blocks bound the (n, M, J) temporary
        dots = np.einsum("njc,mjc->nmj", a[start : start + PAIR_BLOCK], b)
        out[start : start + PAIR_BLOCK] = np.sqrt(np.clip(1.0 - dots**2, 0.0, None)).sum(-1)
    return out


def loop_points(
    local_rot: np.ndarray, search_frames: int, min_frames: int | None = None
) -> tuple[int, int]:
    """``(start, stop)`` frames of the most similar pair with ``start`` among the first
    ``search_frames`` frames and ``stop`` among the last ones, at least ``min_frames`` apart
    (default: half the clip); the loop plays ``start .. stop - 1`` and jumps back.

    Raises:
        SynthesisError: the clip is too short for such a pair.
    """
    n = local_rot.shape[0]
    search = int(min(search_frames, n))
    min_frames = n // 2 if min_frames is None else int(min_frames)
    first = local_rot[:search]
    last_start = n - search
    scores = similarity_matrix(first, local_rot[last_start:])
    gap = (last_start + np.arange(search))[None, :] - np.arange(search)[:, None]
    scores = np.where(gap >= max(min_frames, 1), scores, np.inf)
    if not np.isfinite(scores).any():
        raise SynthesisError(
            f"a {n}-frame clip has no pair of frames {min_frames} apart within its first and "
            f"last {search} frames: record a longer take or search further"
        )
    i, k = np.unravel_index(int(np.argmin(scores)), scores.shape)
    return int(i), int(last_start + k)


def seam_index(local_rot: np.ndarray, start: int, stop: int) -> float:
    """S_i across the seam of a loop ``start .. stop``: the frame it jumps from and to."""
    return float(similarity_index(local_rot[stop], local_rot[start]))

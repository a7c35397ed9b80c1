"""Blending the aligned matches into one pose (CoolMoves §3.1.4).

- Each match gets a "normalized weight (between 0 and 1) ... inversely proportional to the
  distance error": ``w_i = (1 / d_i) / sum_j (1 / d_j)`` over the matches of one hand.
- "The left and right arm's motion will be governed by their respective hand's motion":
  joints of the left limb take the left-hand weights only, the right limb the right-hand ones,
  "for all the other joints ... a weighted average between the left and right arm weights".
  We weight that average by each hand's match confidence (below).
- "We also average out the weights of all the joints to compute a global match weight",
  which weighs the EWMA (§3.1.4; the abstract calls it the "joint prediction probability").
  The paper does not say how a joint's weight becomes one number in [0, 1]; it approximates
  "the likelihood of a motion being applied ... by a function of matching distance"
  (§3.1.3). Ours: a match's likelihood is ``t / (t + d)`` for the KD-tree threshold ``t``
  (1 for an exact match, 1/2 at the threshold, never 0: a heavy-tailed kernel whose
  half-width is the threshold); a hand's confidence is the weighted mean over its matches; a
  limb joint has its hand's confidence, every other joint the mean of both; the global match
  weight is the mean over all joints. A kernel that reaches 0 (``1 - d / t`` floored at 0)
  would give an input farther than the threshold from every database window (2 cm tracking
  jitter, real mocap against a generated database) weight 0 and freeze the output in its pose.
- The trunk and legs weigh the two hands' matches by the hands' confidences, so that a hand
  with poor matches (or untracked) leaves them to the other.

Shapes: ``B`` queries, ``k`` matches per hand, ``M = 2k`` (left matches first), ``J`` joints.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat

_EPS_M = 1e-9  # keeps an exact (distance 0) match finite; it then takes all the weight


def inverse_distance_weights(dist: np.ndarray) -> np.ndarray:
    """``(B, k)`` weights proportional to ``1 / d`` summing to 1 (0 for missing, ``inf``)."""
    dist = np.asarray(dist, float)
    d_min = np.minimum.reduce(dist, axis=-1, keepdims=True)
    # 1/(d + eps) relative to the best match, so that an exact match cannot overflow.
    usable = np.isfinite(dist)
    inv = np.divide(d_min + _EPS_M, dist + _EPS_M, out=np.zeros(dist.shape), where=usable)
    total = np.add.reduce(inv, axis=-1, keepdims=True)
    return np.divide(inv, total, out=np.zeros(inv.shape), where=total > 0)


def match_likelihood(dist: np.ndarray, max_distance: float) -> np.ndarray:
    """``t / (t + d)`` of distances ``d`` for the threshold ``t``: 1 at 0, 1/2 at ``t``, 0
    only for missing (``inf``) matches."""
    return max_distance / (max_distance + np.asarray(dist, float))


def hand_confidence(dist: np.ndarray, weights: np.ndarray, max_distance: float) -> np.ndarray:
    """``(...)`` weighted mean of :func:`match_likelihood` over one hand's matches (the
    last axis of ``dist`` and ``weights``)."""
    return np.add.reduce(weights * match_likelihood(dist, max_distance), axis=-1)


def group_weights(
    dist: np.ndarray, max_distance: float, weights: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Match weights per joint group and each group's confidence.

    Args:
        dist: ``(2, B, k)`` distances of the left and the right hand's matches.
        weights: ``(2, B, k)`` their match weights; by default
            :func:`inverse_distance_weights` of the distances (the mixture variant brings
            its own).
    Returns:
        weights ``(B, 3, M)``: rows for the left limb, the right limb and the rest; each row
        sums to 1 or is all 0 (no match for that group).
        confidence ``(B, 3)`` in [0, 1] for the same groups.
    """
    w = inverse_distance_weights(dist) if weights is None else weights
    (ql, qr), (has_l, has_r) = hand_confidence(dist, w, max_distance), np.add.reduce(w, -1) > 0
    # Trunk and legs: both hands, by confidence (positive wherever a hand has a match).
    share_l = np.where(has_l & has_r, ql / np.maximum(ql + qr, 1e-300), has_l.astype(float))
    _, b, k = w.shape
    out = np.zeros((b, 3, 2 * k))  # filled in place: one step's few rows
    out[:, 0, :k], out[:, 1, k:] = w[0], w[1]
    out[:, 2, :k] = share_l[:, None] * w[0]
    out[:, 2, k:] = (1.0 - share_l)[:, None] * w[1]
    count = has_l.astype(float) + has_r
    confidence = np.zeros((b, 3))
    confidence[:, 0], confidence[:, 1] = ql, qr
    np.divide(ql + qr, count, out=confidence[:, 2], where=count > 0)
    return out, confidence


def joint_groups(limb_masks: np.ndarray) -> np.ndarray:
    """``(J,)`` group of each joint: 0 left limb, 1 right limb, 2 the rest."""
    return np.where(limb_masks[0], 0, np.where(limb_masks[1], 1, 2))


def group_shares(groups: np.ndarray) -> np.ndarray:
    """``(3,)`` share of the joints in each group (``groups (J,)`` from :func:`joint_groups`)."""
    counts = np.bincount(groups, minlength=3).astype(float)
    return counts / counts.sum()


def global_match_weight(confidence: np.ndarray, shares: np.ndarray) -> np.ndarray:
    """``(B,)`` mean over all joints of their group's confidence ``(B, 3)``, given each
    group's share of the joints (:func:`group_shares`)."""
    # One row would take numpy's vector-dot path, whose rounding differs from the matrix-
    # vector product of a batch by an ulp (amplified to 1e-12 in the final rotations): a
    # batch of one is computed as two rows, so streaming stays bit-identical to batch.
    rows = confidence if confidence.shape[0] > 1 else np.concatenate([confidence, confidence])
    return (rows @ shares)[: confidence.shape[0]]


def blend_rotations(rotations: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted average of unit quaternions ``(B, M, J, 4)`` with weights ``(B, J, M)``.

    Each match is first flipped into the hemisphere of the joint's heaviest match, then the
    weighted sum is normalised (the chordal mean, accurate for the nearby rotations that
    matches of one query are). Joints with no weight get a zero quaternion; callers keep their
    previous rotation there.
    """
    b, j = weights.shape[:2]
    heaviest = weights.argmax(axis=-1)  # (B, J)
    ref = rotations[np.arange(b)[:, None], heaviest, np.arange(j)]  # (B, J, 4)
    weights = weights.transpose(0, 2, 1)  # (B, M, J)
    # Each weight signed by its match's hemisphere (negating is exact: w * -1 is -w).
    signed = np.where(quat.dot(rotations, ref[:, None]) < 0, -weights, weights)
    # The sum over matches in order (the sum einsum("bjm,bmj,bmjc->bjc") takes, cheaper).
    summed = np.add.reduce(signed[..., None] * rotations, axis=1)
    norm = np.sqrt(quat.dot(summed, summed))[..., None]  # np.linalg.norm's sum
    return np.divide(summed, norm, out=np.zeros(summed.shape), where=norm > 1e-12)

"""Analytic two-bone inverse kinematics (shoulder-elbow-wrist, hip-knee-ankle) on local rotations.

Shared by the methods: CoolMoves' hand and foot corrections (beyond that paper, which outputs
blended database poses) and AvatarGo's limbs (:mod:`synthesis.avatargo.analytic_ik`, in
place of the paper's Unity IK). It moves a limb's end joint to a target with the closed-form
two-bone solution (law of cosines), as used for arm and leg IK in games (e.g. Unity's
TwoBoneIKConstraint):

- the middle joint (elbow, knee) bends about the normal of its current bend plane, i.e. its
  hinge, until root and end are as far apart as root and target (clipped to the reachable
  range ``[|l1 - l2|, l1 + l2]``): a hinge joint stays a hinge, inside its limits;
- the whole limb then swings at the root by the smallest rotation taking the end onto the
  target, so the bend plane (the elbow or knee pole) is the input pose's, turned as little as
  possible: the input pose (CoolMoves: the blended database pose) decides where the elbow
  points;
- the end joint keeps its global orientation (hand or foot do not tilt).

Vectorised over ``B`` poses and ``S`` limbs (both arms in one pass). Forward kinematics
along the chains (:func:`chain_fk`) with numpy matrices: the hot path of ``step()``
cannot afford scipy ``Rotation`` objects (tens of microseconds each).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat

_EPS = 1e-12
_X, _Z = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


def chain_fk(
    rotations: np.ndarray, root: np.ndarray, offsets: np.ndarray, scale: np.ndarray, chain
) -> tuple[np.ndarray, np.ndarray]:
    """Global rotation matrices ``(B, [S,] L, 3, 3)`` and positions ``(B, [S,] L, 3)`` along
    ``chain``, or along ``S`` chains of one length at once (both arms in one pass).

    Args:
        rotations: ``(B, J, 4)`` local rotations. root: ``(B, 3)`` position of ``chain[0]``.
        offsets: ``(J, 3)`` rest offsets of the unscaled rig; scale: ``(B,)`` bone scale.
        chain: ``(L,)`` or ``(S, L)`` joint indices from the root, each the parent of the next.
    """
    chain = np.asarray(chain)
    # (x.take(i, axis): x[:, i] without advanced indexing's set-up, a step's hot path.)
    mats = quat.unit_to_matrix(rotations.take(chain, axis=1))[..., None, :, :]
    glob = mats[..., 0, :, :, :]  # (B, [S,] 1, 3, 3)
    globs = [glob]
    for link in range(1, chain.shape[-1]):
        glob = glob @ mats[..., link, :, :, :]
        globs.append(glob)
    globs = np.concatenate(globs, axis=-3)  # (B, [S,] L, 3, 3)
    # Each bone's offset in world axes, in one product for the whole chain; the positions
    # are then the running sum from the root (cumsum adds in the order a loop would).
    steps = offsets.take(chain[..., 1:], axis=0)[..., None]  # (S|, L-1, 3, 1)
    scale = np.asarray(scale, float).reshape((-1,) + (1,) * (chain.ndim + 1))
    positions = np.empty(globs.shape[:-1])  # (B, [S,] L, 3)
    positions[..., 0, :] = np.asarray(root, float).reshape((-1,) + (1,) * (chain.ndim - 1) + (3,))
    positions[..., 1:, :] = scale * (globs[..., :-1, :, :] @ steps)[..., 0]
    return globs, positions.cumsum(axis=-2, out=positions)


def _norm(v: np.ndarray) -> np.ndarray:
    """``|v| (..., 1)`` of ``v (..., 3)``: np.linalg.norm's sum, without its Python wrapper."""
    return np.sqrt(np.add.reduce(v * v, axis=-1, keepdims=True))


def unit(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directions ``(..., 3)`` and lengths ``(...)`` of vectors ``v (..., 3)`` (a zero vector
    stays zero): the normalisation :func:`avatar_models.quat.shortest_arc` applies, for
    callers that pass :func:`avatar_models.quat.unit_arc` directions they already have."""
    norm = _norm(v)
    return v / np.maximum(norm, _EPS), norm[..., 0]


def _in_frame(q: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """World rotations ``q (..., 4)`` expressed in the local axes ``frame (..., 3, 3)``:
    ``frame^T R frame`` is the same angle about the axis ``frame^T n``."""
    out = np.empty(q.shape)
    out[..., :1] = q[..., :1]
    out[..., 1:] = (q[..., None, 1:] @ frame)[..., 0, :]
    return out


_BONE_STARTS = np.array([1, 2, 1])
"""Where the vectors of :func:`solve` start: the upper, middle and upper joint."""
_UNDO_LAST = np.array([[1.0, 1, 1, 1], [1, 1, 1, 1], [1, -1, -1, -1]])
"""Conjugates the third of three stacked quaternions (quat.conj's sign pattern)."""


def solve(
    rotations: np.ndarray,
    globs: np.ndarray,
    positions: np.ndarray,
    joints: tuple[int, int, int],
    target: np.ndarray,
) -> np.ndarray:
    """Local rotations ``(B, J, 4)`` with the end joint of ``joints`` moved to ``target``,
    for one limb or ``S`` limbs at once (the bracketed axes).

    Args:
        rotations: ``(B, J, 4)`` local rotations.
        globs, positions: ``(B, [S,] 4, 3, 3)`` and ``(B, [S,] 4, 3)`` global rotations and
            positions of the upper joint's parent, the upper, middle and end joints (from
            :func:`chain_fk`; the parent's position and the end's rotation are not read).
        joints: indices ``(3,)`` or ``(S, 3)`` of the upper, middle and end joints.
        target: ``(B, [S,] 3)`` where the end joint should go.
    """
    a, b = positions[..., 1, :], positions[..., 2, :]
    # The two bones and the upper joint to the target (b - a, c - b, target - a), their
    # directions and lengths, in one difference and one norm (numpy's per-call set-up, not
    # the arithmetic, is what a tick's few vectors cost).
    ends = np.concatenate([positions[..., 2:, :], target[..., None, :]], axis=-2)
    arms = ends - positions.take(_BONE_STARTS, axis=-2)  # (B, [S,] 3, 3)
    units, lengths = unit(arms)
    u1, u2, to_target = units[..., 0, :], units[..., 1, :], units[..., 2, :]
    l1, l2 = lengths[..., 0], lengths[..., 1]
    d = np.minimum(np.maximum(lengths[..., 2], np.abs(l1 - l2) + 1e-9), l1 + l2 - 1e-9)
    # 1. Bend the middle joint about the normal of its current bend plane (its hinge) until
    #    root and end are ``d`` apart (law of cosines on the bend angle u1 -> u2).
    normal, bent = unit(quat.cross(u1, u2))
    straight = bent < 1e-9  # a fully straight limb has no plane: bend about a horizontal axis
    if straight.any():
        fallback, _ = unit(quat.cross(u1, np.where(np.abs(u1[..., 2:]) < 0.9, _Z, _X)))
        normal = np.where(straight[..., None], fallback, normal)
    bend_now = np.arctan2(bent, np.add.reduce(u1 * u2, axis=-1))
    cos_bend = np.minimum(np.maximum((d**2 - l1**2 - l2**2) / (2.0 * l1 * l2), -1.0), 1.0)
    turn_lower = quat.from_axis_angle(normal, np.arccos(cos_bend) - bend_now)
    new_c = b + quat.rotate(turn_lower, arms[..., 1, :])
    # 2. Swing the whole limb at the root, by the smallest rotation, onto the target.
    turn_upper = quat.unit_arc(unit(new_c - a)[0], to_target)
    # The end joint keeps its global rotation: undo both turns in the old middle frame.
    both = quat.mul(turn_upper, turn_lower)
    # The three turns in the frames of the parent, upper and middle joints (the first three
    # of ``globs``) in one product; the middle joint's is undone (conjugated).
    turns = np.concatenate(
        [turn_upper[..., None, :], turn_lower[..., None, :], both[..., None, :]], axis=-2
    )
    turns = _in_frame(turns, globs[..., :3, :, :]) * _UNDO_LAST  # (B, [S,] 3, 4)
    ijk = np.asarray(joints)
    out = rotations.copy()
    out[:, ijk] = quat.mul(turns, rotations[:, ijk])
    return out

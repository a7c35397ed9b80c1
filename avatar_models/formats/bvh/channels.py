"""BVH channel values to joint positions, local rotations and the root's path (see
:mod:`..bvh`). Shapes: ``T`` frames, ``J`` joints."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats.bvh.hierarchy import CHANNELS, BvhJoint

# Position channels whose peak-to-peak is below this fraction of their magnitude are constant
# (files print about 6 significant digits, so "constant" values jitter in the last digit).
_CONSTANT_RTOL = 1e-6


def euler_quaternions(half: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(T, J, 4)`` wxyz of the intrinsic rotations ``q = qa qb qc`` about ``axes (J, 3)`` (a
    permutation of 0, 1, 2 per joint) by the half angles ``half (T, J, 3)``, in closed form.

    With ``e = +1`` for cyclic orders (``e_a x e_b = e_c``) and -1 otherwise, expanding the two
    Hamilton products of elementary quaternions gives
    ``w = ca cb cc - e sa sb sc``, ``a = sa cb cc + e ca sb sc``, ``b = ca sb cc - e sa cb sc``,
    ``c = ca cb sc + e sa sb cc`` (for XYZ the textbook Tait-Bryan formula).
    """
    c, s = np.cos(half), np.sin(half)
    ca, cb, cc = c[..., 0], c[..., 1], c[..., 2]
    sa, sb, sc = s[..., 0], s[..., 1], s[..., 2]
    e = np.where((axes[:, 1] - axes[:, 0]) % 3 == 1, 1.0, -1.0)  # (J,) cyclic or not
    ca_cb, sa_sb, sa_cb, ca_sb = ca * cb, sa * sb, sa * cb, ca * sb
    n_frames, n_joints = half.shape[:2]
    out = np.empty((n_frames, n_joints, 4))
    out[..., 0] = ca_cb * cc - e * sa_sb * sc
    vec = np.stack(
        [sa_cb * cc + e * ca_sb * sc, ca_sb * cc - e * sa_cb * sc, ca_cb * sc + e * sa_sb * cc],
        axis=-1,
    )
    # Scatter slot k of joint j to component 1 + axes[j, k]: one flat fancy assignment
    # (take_along_axis over a small last axis costs ten times more).
    target = 4 * np.arange(n_joints)[:, None] + 1 + axes
    out.reshape(n_frames, -1)[:, target.ravel()] = vec.reshape(n_frames, -1)
    return out


def split_channels(
    joints: list[BvhJoint], values: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per joint: its position ``(T, J, 3)`` (the OFFSET, with each position channel replacing
    its axis), which joints have position channels ``(J,)``, and the local rotations
    ``(T, J, 4)`` wxyz, composed as intrinsic Euler rotations in channel order
    (``q = q1 q2 q3``) in one vectorised pass over all joints. A joint with fewer than three
    rotation channels gets its missing axes last, at angle 0, so every joint's order is a
    permutation of XYZ (:func:`euler_quaternions`).
    """
    n_frames = values.shape[0]
    zero_col = values.shape[1]  # an appended column of zeros: the angle of a missing axis
    slot_col = np.full((len(joints), 3), zero_col)
    slot_axis = np.zeros((len(joints), 3), dtype=int)
    pos_col, pos_slot = [], []  # value column -> flat (joint, axis) slot of the positions
    col = 0
    for j, joint in enumerate(joints):
        axes = []
        for name in joint.channels:
            kind, axis = CHANNELS[name]
            if kind == "position":
                pos_col.append(col)
                pos_slot.append(3 * j + "XYZ".index(axis))
            else:
                slot_col[j, len(axes)] = col
                axes.append("XYZ".index(axis))
            col += 1
        slot_axis[j] = axes + [a for a in range(3) if a not in axes]
    offsets = np.array([j.offset for j in joints])
    positions = np.broadcast_to(offsets.ravel(), (n_frames, offsets.size)).copy()
    positions[:, pos_slot] = values[:, pos_col]
    has_position = np.zeros(len(joints), dtype=bool)
    has_position[np.array(pos_slot, dtype=int) // 3] = True
    padded = np.concatenate([values, np.zeros((n_frames, 1))], axis=1)
    half = padded[:, slot_col] * (np.pi / 360.0)  # (T, J, 3) half angles in radians
    rot = euler_quaternions(half, slot_axis)
    return positions.reshape(n_frames, len(joints), 3), has_position, rot


def _is_constant(a: np.ndarray) -> np.ndarray:
    """``a (T, ..., k)`` -> ``(...)`` bool: every one of the ``k`` columns is constant over
    time up to print precision."""
    scale = np.maximum(1.0, np.abs(a).max(axis=0))
    return np.all(np.ptp(a, axis=0) <= _CONSTANT_RTOL * scale, axis=-1)


def root_and_offsets(
    joints: list[BvhJoint],
    positions: np.ndarray,
    has_position: np.ndarray,
    rot: np.ndarray,
    path: Path,
) -> tuple[np.ndarray, np.ndarray, str]:
    """Root trajectory ``(T, 3)``, offsets ``(J, 3)`` (file units) and the folded joint's name.

    ``positions (T, J, 3)``, ``has_position (J,)``: from :func:`split_channels`;
    ``rot (T, J, 4)``: local rotations in the file's axes.
    """
    offsets = np.array([j.offset for j in joints])
    root = joints[0]
    root_pos = positions[:, 0].copy()
    if has_position[0]:  # the root's channels add to its OFFSET
        present = np.isin(["Xposition", "Yposition", "Zposition"], root.channels)
        root_pos += root.offset * present
    folded = ""
    placed = np.flatnonzero(has_position[1:]) + 1
    stacked = positions[:, placed]
    constant = _is_constant(stacked)  # all joints in one pass: Bandai files place every joint
    offsets[placed] = np.where(constant[:, None], stacked.mean(axis=0), offsets[placed])
    for j in placed[~constant]:
        pos = positions[:, j]
        root_turns = not _is_constant(rot[:, 0])
        only_child = [k for k in range(len(joints)) if joints[k].parent == 0] == [j]
        if joints[j].parent == 0 and not root_turns and only_child:
            root_pos = root_pos + quat.rotate(rot[0, 0], pos)
            offsets[j] = 0.0
            folded = joints[j].name
            continue
        raise MotionFormatError(
            f"joint {joints[j].name!r} has moving position channels; only the root (or the single "
            "child of a root that does not rotate) may translate",
            path,
            joints[j].line,
        )
    return root_pos, offsets, folded

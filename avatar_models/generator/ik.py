"""Rotation helpers and analytic two-bone inverse kinematics, vectorised over frames.

Rotations here are ``(T, 3, 3)`` matrices (world or parent-relative); :mod:`plan` converts
them to the wxyz quaternions that :class:`~avatar_models.motion.Motion` stores.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def axis_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``(T, 3, 3)`` rotations by ``angle (T,)`` radians about the fixed unit ``axis (3,)``."""
    rotvec = np.asarray(angle, dtype=float).reshape(-1, 1) * np.asarray(axis, dtype=float)
    return Rotation.from_rotvec(rotvec).as_matrix()


def euler(angles: np.ndarray, order: str = "xyz") -> np.ndarray:
    """``(T, 3, 3)`` rotations from extrinsic Euler ``angles (T, 3)`` radians."""
    return Rotation.from_euler(order, np.asarray(angles, dtype=float).reshape(-1, 3)).as_matrix()


def scale_rotation(rot: np.ndarray, factor: float) -> np.ndarray:
    """``(T, 3, 3)`` rotations with their angle times ``factor`` about the same axis."""
    return Rotation.from_rotvec(Rotation.from_matrix(rot).as_rotvec() * factor).as_matrix()


def twist_about(rot: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``(T, 3, 3)`` twist part of ``rot (T, 3, 3)`` about ``axis (3,)`` (swing-twist
    decomposition ``rot = swing @ twist``, the swing moving ``axis`` along the shortest arc)."""
    axis = _unit(np.asarray(axis, dtype=float))
    xyzw = Rotation.from_matrix(rot).as_quat()
    angle = 2.0 * np.arctan2(xyzw[:, :3] @ axis, xyzw[:, 3])
    return axis_rotation(axis, angle)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def two_bone_ik(
    base_pos: np.ndarray,
    parent_rot: np.ndarray,
    upper_offset: np.ndarray,
    lower_offset: np.ndarray,
    hinge: np.ndarray,
    target: np.ndarray,
    pole: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Analytic IK of a limb (hip-knee-ankle, shoulder-elbow-wrist) with a hinge middle joint.

    Args:
        base_pos: ``(T, 3)`` world position of the upper joint (hip, shoulder).
        parent_rot: ``(T, 3, 3)`` world rotation of the upper joint's parent.
        upper_offset, lower_offset: ``(3,)`` rest offsets of the middle and end joints; both
            perpendicular to ``hinge`` (a straight limb in rest, as in the avatar rig).
        hinge: ``(3,)`` unit axis of the middle joint in its local frame, signed so that a
            positive angle bends the limb the anatomical way.
        target: ``(T, 3)`` world position wanted for the end joint; clamped to the reachable
            shell when too far or too near.
        pole: ``(T, 3)`` world direction the middle joint should point to (knee forward,
            elbow backward/outward); must not be parallel to the limb.

    Returns:
        ``(upper_local, middle_local, upper_world)``, each ``(T, 3, 3)``: the local rotations
        of the upper and middle joints and the world rotation of the upper joint.
    """
    a = float(np.linalg.norm(upper_offset))
    b = float(np.linalg.norm(lower_offset))
    reach = target - base_pos
    dist = np.clip(np.linalg.norm(reach, axis=-1), abs(a - b) + 1e-6, (a + b) * (1.0 - 1e-6))
    # Law of cosines: the bend angle from straight, 0 for a fully extended limb.
    bend = np.arccos(np.clip((dist**2 - a * a - b * b) / (2.0 * a * b), -1.0, 1.0))
    middle_local = axis_rotation(hinge, bend)
    limb_local = upper_offset + np.einsum("tab,b->ta", middle_local, lower_offset)
    # Frame (limb direction, hinge axis) in the upper joint's local frame and in the world.
    e1 = _unit(limb_local)
    e3 = np.broadcast_to(_unit(hinge), e1.shape)
    local_frame = np.stack([e1, np.cross(e3, e1), e3], axis=-1)
    f1 = _unit(reach)
    f3 = _unit(np.cross(pole, f1))
    world_frame = np.stack([f1, np.cross(f3, f1), f3], axis=-1)
    upper_world = world_frame @ np.swapaxes(local_frame, -1, -2)
    upper_local = np.swapaxes(parent_rot, -1, -2) @ upper_world
    return upper_local, middle_local, upper_world

"""Spine bend from the headset and the back tracker (AvatarGo §3.3 eq. 1, §3.4 eq. 4).

At the walk-in T-pose AvatarGo stores ``w0 = p0(T_head) - p0(T_root)`` (eq. 1), the vector
from the back tracker to the headset. At run time the back bends by
``alpha_t = angle(w0, w_t)`` (eq. 4), about the axis ``w0 x w_t`` that turns one into the
other, applied to the spine by forward kinematics. Ours applies it to the avatar's rest
pelvis-to-neck vector and gives the bent neck position to the IK as a soft target.
"""

from __future__ import annotations

import numpy as np

from avatar_models import quat

MIN_AXIS = 1e-9
"""Below this ``|w0 x w_t| / (|w0| |w_t|)`` the two vectors are parallel: no bend."""


def bend_angle(w0: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``alpha_t (B,)`` radians between ``w0 (3,)`` and ``w (B, 3)`` (eq. 4)."""
    cross = np.linalg.norm(np.cross(w0, w), axis=-1)
    return np.arctan2(cross, w @ w0)


def spine_bend(w0: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``(B, 4)`` wxyz rotations by ``alpha_t`` about ``w0 x w_t`` (identity where parallel):
    each turns the direction of ``w0 (3,)`` onto that of ``w (B, 3)``."""
    axis = np.cross(w0, w)
    norm = np.linalg.norm(axis, axis=-1, keepdims=True)
    scale = np.linalg.norm(w0) * np.linalg.norm(w, axis=-1, keepdims=True)
    parallel = norm <= MIN_AXIS * scale
    axis = np.where(parallel, [0.0, 0.0, 1.0], axis / np.where(parallel, 1.0, norm))
    alpha = np.where(parallel[..., 0], 0.0, bend_angle(w0, w))
    return quat.from_axis_angle(axis, alpha)

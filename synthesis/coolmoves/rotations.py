"""Quaternion <-> rotation matrix and intrinsic Euler angles in plain numpy, for the hot path.

Why not scipy here: ``step()`` converts about twenty joints per 90 Hz sample, and building a
``scipy.spatial.transform.Rotation`` costs tens of microseconds of Python-level set-up per
call, more than the arithmetic itself (three Euler round trips were a third of the per-step
time). The formulas below are the textbook ones and are checked against scipy in the tests.

Euler convention (scipy's upper-case, intrinsic): order ``"abc"`` means
``R = R_a(alpha) R_b(beta) R_c(gamma)``, angles ``(alpha, beta, gamma)``; only Tait-Bryan
orders (three different axes) are supported, which is all joint limits use. Quaternions are
wxyz.
"""

from __future__ import annotations

import numpy as np

from avatar_models import quat

_AXES = {"X": 0, "Y": 1, "Z": 2}


def to_matrix(q: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` wxyz -> rotation matrices ``(..., 3, 3)``."""
    w, x, y, z = np.moveaxis(np.asarray(q, float), -1, 0)
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    m = np.stack(
        [
            1 - 2 * (yy + zz),
            2 * (xy - wz),
            2 * (xz + wy),
            2 * (xy + wz),
            1 - 2 * (xx + zz),
            2 * (yz - wx),
            2 * (xz - wy),
            2 * (yz + wx),
            1 - 2 * (xx + yy),
        ],
        axis=-1,
    )
    return m.reshape(*m.shape[:-1], 3, 3)


def euler_axes(orders: str | list[str]) -> np.ndarray:
    """Axis indices ``(G, 3)`` (x=0, y=1, z=2) of ``G`` Tait-Bryan orders such as ``"YXZ"``."""
    orders = [orders] if isinstance(orders, str) else list(orders)
    axes = np.array([[_AXES[a] for a in o.upper()] for o in orders])
    if axes.shape[1:] != (3,) or any(len(set(a)) != 3 for a in axes):
        raise ValueError(f"Euler orders {orders!r} are not Tait-Bryan (three different axes)")
    return axes


def to_euler(q: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(..., G, 4)`` wxyz -> ``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)``.

    With ``R = R_i(a) R_j(b) R_k(c)`` and ``e`` the order's parity (+1 for XYZ, YZX, ZXY):
    ``sin b = e R[i, k]``, ``a = atan2(-e R[j, k], R[k, k])``, ``c = atan2(-e R[i, j], R[i, i])``
    (at ``|b| = pi / 2`` only ``a + e c`` is defined; the split then follows rounding).
    """
    i, j, k = np.asarray(axes).T
    e = np.where((j - i) % 3 == 1, 1.0, -1.0)
    m = to_matrix(q)
    g = np.arange(m.shape[-3])
    b = np.arcsin(np.clip(e * m[..., g, i, k], -1.0, 1.0))
    a = np.arctan2(-e * m[..., g, j, k], m[..., g, k, k])
    c = np.arctan2(-e * m[..., g, i, j], m[..., g, i, i])
    return np.stack([a, b, c], axis=-1)


def from_euler(angles: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)`` -> ``(..., G, 4)`` wxyz."""
    angles = np.asarray(angles, float)
    half = 0.5 * angles
    # One elementary quaternion per angle (cos, sin on its axis), then their product.
    parts = np.zeros(angles.shape + (4,))
    parts[..., 0] = np.cos(half)
    on_axis = np.broadcast_to(1 + np.asarray(axes), angles.shape)[..., None]
    np.put_along_axis(parts, on_axis, np.sin(half)[..., None], axis=-1)
    return quat.mul(quat.mul(parts[..., 0, :], parts[..., 1, :]), parts[..., 2, :])

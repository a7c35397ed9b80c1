"""Vectorised quaternion algebra, scalar-first ``(w, x, y, z)`` as MuJoCo.

All functions broadcast over leading axes: ``q`` has shape ``(..., 4)``, vectors ``(..., 3)``.
Heavier operations (Euler angles, slerp, averaging) go through :mod:`scipy.spatial.transform`;
only the few products used on the forward-kinematics hot path are written here, because
building a ``Rotation`` object per joint costs more than the arithmetic itself.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def to_scipy(q: np.ndarray) -> Rotation:
    """``(..., 4)`` wxyz -> scipy ``Rotation`` (flattened over leading axes)."""
    q = np.asarray(q, dtype=float)
    return Rotation.from_quat(q.reshape(-1, 4)[:, [1, 2, 3, 0]])


def from_scipy(r: Rotation, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """scipy ``Rotation`` -> wxyz array, reshaped to ``shape + (4,)`` if given."""
    xyzw = np.atleast_2d(r.as_quat())
    q = xyzw[:, [3, 0, 1, 2]]
    return q if shape is None else q.reshape(*shape, 4)


def normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternions, sign chosen with ``w >= 0``."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    # Component views by indexing: cheaper than moveaxis on the small arrays of a hot path.
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def conj(q: np.ndarray) -> np.ndarray:
    """Conjugate (the inverse of a unit quaternion)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v (..., 3)`` by unit quaternions ``q (..., 4)``."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def to_matrix(q: np.ndarray) -> np.ndarray:
    """``(..., 4)`` -> rotation matrices ``(..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    return to_scipy(q).as_matrix().reshape(*q.shape[:-1], 3, 3)


def from_matrix(m: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` -> wxyz ``(..., 4)``."""
    m = np.asarray(m, dtype=float)
    return from_scipy(Rotation.from_matrix(m.reshape(-1, 3, 3)), m.shape[:-2])


def from_axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation of ``angle (...)`` radians about unit ``axis (..., 3)`` or a fixed ``(3,)`` axis."""
    axis = np.asarray(axis, dtype=float)
    angle = np.asarray(angle, dtype=float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    half = 0.5 * angle[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def angle(q: np.ndarray) -> np.ndarray:
    """Rotation angle in ``[0, pi]`` of each quaternion."""
    q = np.asarray(q, dtype=float)
    return 2.0 * np.arctan2(np.linalg.norm(q[..., 1:], axis=-1), np.abs(q[..., 0]))


def yaw(q: np.ndarray) -> np.ndarray:
    """Heading angle about +Z of each rotation's +X axis (radians)."""
    # The x and y of rotate(q, +X), written out: equal to the last bit, without the two
    # cross products (a per-frame hot path of the physics controller).
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def make_continuous(q: np.ndarray, axis: int = 0) -> np.ndarray:
    """Flip signs along ``axis`` so consecutive quaternions lie in one hemisphere."""
    q = np.moveaxis(np.array(q, dtype=float), axis, 0)
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    flips = np.concatenate([np.zeros((1,) + dots.shape[1:]), np.cumsum(dots < 0, axis=0)])
    q = np.where((flips % 2 == 1)[..., None], -q, q)
    return np.moveaxis(q, 0, axis)

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

from functools import cache

import numpy as np

from avatar_models import quat

_AXES = {"X": 0, "Y": 1, "Z": 2}


def _quadratic_forms() -> np.ndarray:
    """``(16, 9)`` map from the outer product ``q q^T`` (flattened) of a unit wxyz quaternion
    to its rotation matrix (flattened, row-major): every entry is a quadratic form in ``q``,
    e.g. ``R00 = w^2 + x^2 - y^2 - z^2`` (the homogeneous form of ``1 - 2 (y^2 + z^2)``)."""
    forms = np.zeros((4, 4, 3, 3))
    w, x, y, z = range(4)
    for i, j, sign in ((w, w, 1), (x, x, 1), (y, y, -1), (z, z, -1)):
        forms[i, j, 0, 0] = sign
    for i, j, sign in ((w, w, 1), (x, x, -1), (y, y, 1), (z, z, -1)):
        forms[i, j, 1, 1] = sign
    for i, j, sign in ((w, w, 1), (x, x, -1), (y, y, -1), (z, z, 1)):
        forms[i, j, 2, 2] = sign
    # Off-diagonal entries 2 (a b +- c d), split over the symmetric pair (a, b), (b, a).
    for (r, c), terms in {
        (0, 1): ((x, y, 1), (w, z, -1)),
        (0, 2): ((x, z, 1), (w, y, 1)),
        (1, 0): ((x, y, 1), (w, z, 1)),
        (1, 2): ((y, z, 1), (w, x, -1)),
        (2, 0): ((x, z, 1), (w, y, -1)),
        (2, 1): ((y, z, 1), (w, x, 1)),
    }.items():
        for i, j, sign in terms:
            forms[i, j, r, c] += sign
            forms[j, i, r, c] += sign
    return forms.reshape(16, 9)


_FORMS = _quadratic_forms()


def to_matrix(q: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` wxyz -> rotation matrices ``(..., 3, 3)``.

    One outer product and one matrix product (:func:`_quadratic_forms`): a handful of numpy
    calls whatever the batch shape, where the entry-by-entry formula takes about thirty."""
    q = np.asarray(q, float)
    outer = (q[..., :, None] * q[..., None, :]).reshape(*q.shape[:-1], 16)
    return (outer @ _FORMS).reshape(*q.shape[:-1], 3, 3)


def euler_axes(orders: str | list[str]) -> np.ndarray:
    """Axis indices ``(G, 3)`` (x=0, y=1, z=2) of ``G`` Tait-Bryan orders such as ``"YXZ"``."""
    orders = [orders] if isinstance(orders, str) else list(orders)
    axes = np.array([[_AXES[a] for a in o.upper()] for o in orders])
    if axes.shape[1:] != (3,) or any(len(set(a)) != 3 for a in axes):
        raise ValueError(f"Euler orders {orders!r} are not Tait-Bryan (three different axes)")
    return axes


@cache
def _euler_forms(axes: tuple[tuple[int, int, int], ...]) -> np.ndarray:
    """``(G, 16, 5)`` quadratic forms (:func:`_quadratic_forms`) of ``e R[i,k]``,
    ``-e R[j,k]``, ``R[k,k]``, ``-e R[i,j]``, ``R[i,i]`` per order: what :func:`to_euler`
    needs of each joint's matrix, signs included."""
    i, j, k = np.array(axes).T
    e = np.where((j - i) % 3 == 1, 1.0, -1.0)
    rows, cols = np.stack([i, j, k, i, i]), np.stack([k, k, k, j, i])  # (5, G)
    forms = _FORMS.reshape(16, 3, 3)[:, rows, cols] * np.stack([e, -e, 1 + 0 * e, -e, 1 + 0 * e])
    return np.ascontiguousarray(forms.transpose(2, 0, 1))


@cache
def _euler_products(axes: tuple[tuple[int, int, int], ...]) -> np.ndarray:
    """``(G, 8, 4)`` map from the eight products ``(cos|sin a/2)(cos|sin b/2)(cos|sin c/2)``
    (sine bits ``abc`` in binary, ``a`` most significant) to the wxyz quaternion
    ``q_i(a) q_j(b) q_k(c)``: each product of basis elements is one signed basis element."""
    basis = np.eye(4)
    out = np.zeros((len(axes), 8, 4))
    for g, order in enumerate(axes):
        for bits in range(8):
            parts = [
                basis[1 + ax] if bits >> (2 - n) & 1 else basis[0] for n, ax in enumerate(order)
            ]
            out[g, bits] = quat.mul(quat.mul(parts[0], parts[1]), parts[2])
    return out


def _key(axes: np.ndarray) -> tuple[tuple[int, int, int], ...]:
    return tuple(map(tuple, np.asarray(axes).tolist()))


def to_euler(q: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(..., G, 4)`` wxyz -> ``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)``.

    With ``R = R_i(a) R_j(b) R_k(c)`` and ``e`` the order's parity (+1 for XYZ, YZX, ZXY):
    ``sin b = e R[i, k]``, ``a = atan2(-e R[j, k], R[k, k])``, ``c = atan2(-e R[i, j], R[i, i])``
    (at ``|b| = pi / 2`` only ``a + e c`` is defined; the split then follows rounding).
    """
    q = np.asarray(q, float)
    outer = (q[..., :, None] * q[..., None, :]).reshape(*q.shape[:-1], 1, 16)
    entries = (outer @ _euler_forms(_key(axes)))[..., 0, :]  # (..., G, 5)
    b = np.arcsin(np.clip(entries[..., 0], -1.0, 1.0))
    ac = np.arctan2(entries[..., 1::2], entries[..., 2::2])  # a and c
    return np.stack([ac[..., 0], b, ac[..., 1]], axis=-1)


def from_euler(angles: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)`` -> ``(..., G, 4)`` wxyz."""
    half = 0.5 * np.asarray(angles, float)
    cos, sin = np.cos(half), np.sin(half)
    c0, c1, c2 = (np.stack([cos[..., n], sin[..., n]], axis=-1) for n in range(3))
    products = c0[..., :, None, None] * c1[..., None, :, None] * c2[..., None, None, :]
    flat = products.reshape(*half.shape[:-1], 1, 8)
    return (flat @ _euler_products(_key(axes)))[..., 0, :]

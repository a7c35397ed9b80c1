"""Vectorised quaternion algebra, scalar-first ``(w, x, y, z)`` as MuJoCo.

All functions broadcast over leading axes: ``q`` has shape ``(..., 4)``, vectors ``(..., 3)``.
This is the one rotation layer of the project: heavier operations (averaging, Euler
angles of one order) go through :mod:`scipy.spatial.transform` (:func:`to_scipy`,
:func:`from_scipy`, the only conversions to its ``(x, y, z, w)``); the products of the
forward-kinematics hot path, :func:`unit_to_matrix`, the per-joint-order Euler angles
(:func:`to_euler`, :func:`from_euler`) and the slerp step (:func:`power`) are written here,
because building a ``Rotation`` object per call costs more than the arithmetic itself.
"""

from __future__ import annotations

from functools import cache

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
    q = q / np.sqrt(np.add.reduce(q * q, axis=-1, keepdims=True))  # np.linalg.norm's sum
    return np.where(q[..., :1] < 0, -q, q)


_MUL_ORDER = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_MUL_SIGNS = np.array([[1, 1, 1, 1], [-1, 1, -1, 1], [-1, 1, 1, -1], [-1, -1, 1, 1.0]])


def mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    # Row i holds a_i times the components of b that a_i multiplies, signed: row 1 is
    # (-ax bx, ax bw, -ax bz, ax by). Summing the rows in order is the textbook
    # ``aw bw - ax bx - ay by - az bz, ...`` to the bit, in a handful of numpy calls where
    # sixteen products and a stack took thirty (quat.mul runs in every IK step). b.take,
    # not b[..., _MUL_ORDER]: the same gather without advanced indexing's set-up (a third
    # of a tick-sized product's time). The rows are summed by one reduction over the row
    # axis, which numpy adds row after row (an outer axis: no pairwise summation), so the
    # order stays the textbook's, in one call where three additions took three.
    terms = a[..., :, None] * (b.take(_MUL_ORDER, axis=-1) * _MUL_SIGNS)  # (..., 4, 4)
    return np.add.reduce(terms, axis=-2)


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``sum(a * b, axis=-1)`` of quaternions ``(..., 4)``, component by component.

    The same sum in the same order (numpy adds four terms one after the other), without a
    reduction over a length-4 axis, whose per-element loop set-up costs more than the
    arithmetic: 2.5 times faster on the ``(10, 72, 4)`` matches of one CoolMoves step.
    """
    p = np.asarray(a, float) * b
    return ((p[..., 0] + p[..., 1]) + p[..., 2]) + p[..., 3]


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
    t = 2.0 * cross(u, v)
    return v + w * t + cross(u, t)


_YZX, _ZXY = np.array([1, 2, 0]), np.array([2, 0, 1])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` over the last axis ``(..., 3)``: ``(ay bz - az by, az bx - ax bz,
    ax by - ay bx)``, by permuted components (np.cross's moveaxis set-up costs more than
    the arithmetic on a step's few vectors, and would be most of AvatarGo's goals)."""
    # take, not a[..., _YZX]: the same gather without advanced indexing's set-up.
    return a.take(_YZX, axis=-1) * b.take(_ZXY, axis=-1) - a.take(_ZXY, axis=-1) * b.take(
        _YZX, axis=-1
    )


_ARC_EPS = 1e-12
_X_AXIS, _Y_AXIS = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])


def shortest_arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(..., 4)`` smallest rotations turning the directions of ``a`` onto ``b`` ``(..., 3)``.

    Edge cases: the identity where either vector is (near) zero; for opposite directions,
    which have no single smallest rotation, a half turn about an axis perpendicular to ``a``
    (about ``a x X``, or ``a x Y`` when ``a`` is near X), so the result still turns ``a``
    onto ``b``.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    return unit_arc(a / np.maximum(_len(a), _ARC_EPS), b / np.maximum(_len(b), _ARC_EPS))


def unit_arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`shortest_arc` of directions ``a``, ``b`` ``(..., 3)`` already of unit length
    (or zero): the step's hot path, which has normalised them already."""
    cos = np.add.reduce(a * b, axis=-1, keepdims=True)
    q = np.concatenate([1.0 + cos, cross(a, b)], axis=-1)
    opposite = q[..., :1] <= _ARC_EPS
    if opposite.any():
        helper = np.where(np.abs(a[..., :1]) < 0.9, _X_AXIS, _Y_AXIS)
        half_turn = np.concatenate([np.zeros_like(cos), cross(a, helper)], axis=-1)
        q = np.where(opposite, half_turn, q)
    norm = _len(q)
    # Zero input: q is (1, 0, 0, 0) already; a zero helper axis (a itself zero) is identity.
    return np.where(norm > _ARC_EPS, q / np.maximum(norm, _ARC_EPS), IDENTITY)


def _len(v: np.ndarray) -> np.ndarray:
    """``|v| (..., 1)`` over the last axis (np.linalg.norm's sum, without its wrapper)."""
    return np.sqrt(np.add.reduce(v * v, axis=-1, keepdims=True))


def to_matrix(q: np.ndarray) -> np.ndarray:
    """``(..., 4)`` -> rotation matrices ``(..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    return to_scipy(q).as_matrix().reshape(*q.shape[:-1], 3, 3)


def from_matrix(m: np.ndarray, orthonormal: bool = False) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` -> wxyz ``(..., 4)``.

    ``orthonormal=True`` promises proper rotations (products of rotation matrices, as the
    generator's): scipy then skips its determinant and orthogonality checks, which cost
    about 20 times the conversion itself (profiled: most of a generated clip's planning).
    """
    m = np.asarray(m, dtype=float)
    r = Rotation.from_matrix(m.reshape(-1, 3, 3), assume_valid=orthonormal)
    return from_scipy(r, m.shape[:-2])


# -- the hot path without scipy ---------------------------------------------------------
# ``step()`` of a synthesiser converts about twenty joints per 90 Hz sample, and building a
# ``Rotation`` costs tens of microseconds of Python-level set-up per call, more than the
# arithmetic itself (through scipy, three Euler round trips would take a third of a CoolMoves
# step). The formulas are the textbook ones and are checked against scipy in the tests.
#
# Euler convention (scipy's upper-case, intrinsic): order ``"abc"`` means
# ``R = R_a(alpha) R_b(beta) R_c(gamma)``, angles ``(alpha, beta, gamma)``; only Tait-Bryan
# orders (three different axes) are supported, each joint with its own order in one call.

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


def unit_to_matrix(q: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` wxyz -> rotation matrices ``(..., 3, 3)``, without scipy.

    :func:`to_matrix` for the hot path: no normalisation (the input must be unit) and no
    ``Rotation`` set-up; one outer product and one matrix product (:func:`_quadratic_forms`),
    a handful of numpy calls whatever the batch shape. The product is stacked, one
    ``(1, 16) @ (16, 9)`` per quaternion, so that each matrix is the same whatever the batch:
    a single ``(N, 16) @ (16, 9)`` goes to a BLAS kernel that sums in an order which depends
    on ``N`` (OpenBLAS's AVX-512 kernels do), and a synthesiser's ``step`` (a batch of one)
    would then differ from its ``run`` in the last bit."""
    q = np.asarray(q, float)
    outer = (q[..., :, None] * q[..., None, :]).reshape(*q.shape[:-1], 1, 16)
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
            out[g, bits] = mul(mul(parts[0], parts[1]), parts[2])
    return out


def euler_key(axes: np.ndarray) -> tuple[tuple[int, int, int], ...]:
    """``axes (G, 3)`` as a tuple of tuples: what :func:`to_euler` and :func:`from_euler`
    look their tables up by. Callers that convert every frame may pass this instead of the
    array, once converted (the conversion costs as much as a numpy call)."""
    if isinstance(axes, tuple):
        return axes
    return tuple(map(tuple, np.asarray(axes).tolist()))


def to_euler(q: np.ndarray, axes: np.ndarray | tuple) -> np.ndarray:
    """``(..., G, 4)`` wxyz -> ``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)``
    (or their :func:`euler_key`).

    With ``R = R_i(a) R_j(b) R_k(c)`` and ``e`` the order's parity (+1 for XYZ, YZX, ZXY):
    ``sin b = e R[i, k]``, ``a = atan2(-e R[j, k], R[k, k])``, ``c = atan2(-e R[i, j], R[i, i])``
    (at ``|b| = pi / 2`` only ``a + e c`` is defined; the split then follows rounding).
    """
    q = np.asarray(q, float)
    outer = (q[..., :, None] * q[..., None, :]).reshape(*q.shape[:-1], 1, 16)
    entries = (outer @ _euler_forms(euler_key(axes)))[..., 0, :]  # (..., G, 5)
    angles = np.empty(entries.shape[:-1] + (3,))
    np.arctan2(entries[..., 1::2], entries[..., 2::2], out=angles[..., ::2])  # a and c
    # np.clip's numbers, without its Python-level wrapper (a step calls this per sample).
    np.arcsin(np.minimum(np.maximum(entries[..., 0], -1.0), 1.0), out=angles[..., 1])
    return angles


def from_euler(angles: np.ndarray, axes: np.ndarray | tuple) -> np.ndarray:
    """``(..., G, 3)`` intrinsic Euler angles about ``axes (G|1, 3)`` (or their
    :func:`euler_key`) -> ``(..., G, 4)`` wxyz."""
    half = 0.5 * np.asarray(angles, float)
    pairs = np.empty(half.shape + (2,))  # (..., G, 3, cos|sin)
    np.cos(half, out=pairs[..., 0])
    np.sin(half, out=pairs[..., 1])
    c0, c1, c2 = pairs[..., 0, :], pairs[..., 1, :], pairs[..., 2, :]
    products = c0[..., :, None, None] * c1[..., None, :, None] * c2[..., None, None, :]
    flat = products.reshape(*half.shape[:-1], 1, 8)
    return (flat @ _euler_products(euler_key(axes)))[..., 0, :]


def from_axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation of ``angle (...)`` radians about unit ``axis (..., 3)`` or a fixed ``(3,)`` axis."""
    axis = np.asarray(axis, dtype=float)
    angle = np.asarray(angle, dtype=float)
    axis = axis / np.sqrt(np.add.reduce(axis * axis, axis=-1, keepdims=True))  # its norm
    half = 0.5 * angle[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def power(q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``q ** t``: unit quaternions ``q (..., 4)`` scaled along their shortest arc by ``t
    (...)``, i.e. ``exp(t log q)``, the step of a slerp (``slerp(a, b, t) = a (a^-1 b)^t``).

    Written here, not with scipy's ``Slerp``: over a whole clip (frames x joints) scipy's
    per-rotation products cost about 40 times these array operations.
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0, -q, q)  # the shortest arc: the angle below pi
    sin_half = np.linalg.norm(q[..., 1:], axis=-1)
    half = np.arctan2(sin_half, q[..., 0])  # half the rotation angle, in [0, pi/2]
    t = np.asarray(t, dtype=float)
    # sin(t half) / sin(half) -> t as the angle -> 0; where it is 0 the axis part is 0 anyway
    scale = np.sin(t * half) / np.where(sin_half > 0, sin_half, 1.0)
    return np.concatenate([np.cos(t * half)[..., None], q[..., 1:] * scale[..., None]], -1)


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

"""Quaternion helpers agree with scipy's Rotation (the independent reference)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from avatarsim.avatar_models import quat


def test_mul_rotate_conj_match_scipy():
    rng = np.random.default_rng(0)
    a, b = Rotation.random(50, random_state=rng), Rotation.random(50, random_state=rng)
    qa, qb = quat.from_scipy(a), quat.from_scipy(b)
    v = rng.normal(size=(50, 3))
    np.testing.assert_allclose(quat.to_matrix(quat.mul(qa, qb)), (a * b).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(quat.rotate(qa, v), a.apply(v), atol=1e-12)
    np.testing.assert_allclose(quat.to_matrix(quat.conj(qa)), a.inv().as_matrix(), atol=1e-12)
    np.testing.assert_allclose(quat.angle(qa), a.magnitude(), atol=1e-12)


def test_mul_dot_cross_are_the_textbook_sums_to_the_bit():
    """The hot-path forms (permuted components, no length-4 reductions) compute the textbook
    expressions in the textbook order: streaming CoolMoves relies on bit-identical sums."""
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(2, 200, 4))
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    textbook = np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )
    np.testing.assert_array_equal(quat.mul(a, b), textbook)
    np.testing.assert_array_equal(quat.mul(a[0], b), quat.mul(np.broadcast_to(a[0], b.shape), b))
    np.testing.assert_array_equal(quat.dot(a, b), np.sum(a * b, axis=-1))
    u, v = a[:, 1:], b[:, 1:]
    np.testing.assert_array_equal(quat.cross(u, v), np.cross(u, v))


def test_power_is_scipy_slerp_step():
    rng = np.random.default_rng(4)
    a, b = Rotation.random(40, random_state=rng), Rotation.random(40, random_state=rng)
    t = rng.uniform(0, 1, 40)
    expected = [Slerp([0, 1], Rotation.concatenate([a[k], b[k]]))(t[k]) for k in range(40)]
    qa, qb = quat.from_scipy(a), quat.from_scipy(b)
    # Either sign of the step quaternion means the same rotation: power takes the short arc.
    step = quat.mul(quat.conj(qa), qb) * rng.choice([-1.0, 1.0], (40, 1))
    got = quat.to_matrix(quat.mul(qa, quat.power(step, t)))
    np.testing.assert_allclose(got, [r.as_matrix() for r in expected], atol=1e-12)
    np.testing.assert_allclose(quat.power(step, 0.0), np.tile(quat.IDENTITY, (40, 1)), atol=0)
    tiny = quat.from_axis_angle([0, 1, 0], np.array([0.0, 1e-300]))
    np.testing.assert_array_equal(quat.power(tiny, 0.5), np.tile(quat.IDENTITY, (2, 1)))


def test_from_matrix_of_orthonormal_matrices_skips_checks_with_same_result():
    m = Rotation.random(30, random_state=5).as_matrix()
    np.testing.assert_allclose(
        np.abs(np.sum(quat.from_matrix(m, orthonormal=True) * quat.from_matrix(m), -1)), 1.0
    )


def test_axis_angle_yaw_and_continuity():
    q = quat.from_axis_angle([0, 0, 1], np.array([0.3, -2.0]))
    np.testing.assert_allclose(quat.yaw(q), [0.3, -2.0])
    flipped = q.copy()
    flipped[1] *= -1
    seq = quat.make_continuous(np.stack([q[0], flipped[1], q[1]]))
    assert np.all(np.sum(seq[1:] * seq[:-1], axis=-1) >= 0)


@pytest.mark.parametrize("order", ["XYZ", "YXZ", "ZXY", "XZY", "YZX", "ZYX"])
def test_numpy_euler_matches_scipy(order):
    rots = Rotation.random(200, random_state=11)
    q = quat.from_scipy(rots)[:, None]  # (200, 1, 4): one joint
    axes = quat.euler_axes(order)
    np.testing.assert_allclose(quat.to_euler(q, axes)[:, 0], rots.as_euler(order), atol=1e-9)
    np.testing.assert_allclose(quat.unit_to_matrix(q)[:, 0], rots.as_matrix(), atol=1e-12)
    back = quat.from_euler(quat.to_euler(q, axes), axes)[:, 0]
    np.testing.assert_allclose(np.abs(np.sum(back * q[:, 0], axis=-1)), 1.0, atol=1e-12)


def test_conversions_do_not_depend_on_the_batch():
    """A quaternion's matrix and Euler angles are the same bits alone as in a batch: a
    synthesiser's ``step`` (a batch of one) must equal its ``run`` (OpenBLAS's AVX-512 GEMM
    sums a ``(N, 16) @ (16, 9)`` product in an order that depends on ``N``)."""
    q = np.random.default_rng(3).normal(size=(20, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    axes = quat.euler_axes("YXZ")
    alone = np.stack([quat.unit_to_matrix(q[i : i + 1])[0] for i in range(len(q))])
    assert np.array_equal(quat.unit_to_matrix(q), alone)
    euler = quat.to_euler(q[:, None], axes)
    alone = np.stack([quat.to_euler(q[i : i + 1, None], axes)[0] for i in range(len(q))])
    assert np.array_equal(euler, alone)
    back = np.stack([quat.from_euler(euler[i : i + 1], axes)[0] for i in range(len(q))])
    assert np.array_equal(quat.from_euler(euler, axes), back)


def test_shortest_arc_is_scipys_aligning_rotation_of_the_two_directions():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(40, 3)), rng.normal(size=(40, 3)) * 3.0
    q = quat.shortest_arc(a, b)
    for qi, ai, bi in zip(q, a, b, strict=True):
        # scipy's align_vectors with one pair gives the smallest rotation taking ai onto bi
        expected, _ = Rotation.align_vectors(bi[None], ai[None])
        assert (quat.to_scipy(qi).inv() * expected).magnitude() < 1e-9
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0)


@pytest.mark.parametrize("a", [[1.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.3, -0.4, 0.5]])
def test_shortest_arc_of_opposite_directions_is_a_half_turn_onto_b(a):
    a = np.array(a)
    q = quat.shortest_arc(a, -a)
    assert abs(q[0]) < 1e-12  # a half turn
    np.testing.assert_allclose(quat.rotate(q, a), -a, atol=1e-12)
    assert abs(q[1:] @ a) < 1e-12  # about an axis perpendicular to a


def test_shortest_arc_of_a_zero_vector_is_the_identity():
    zero, v = np.zeros(3), np.array([0.0, 1.0, 0.0])
    for a, b in ((zero, v), (v, zero), (zero, zero)):
        np.testing.assert_array_equal(quat.shortest_arc(a, b), quat.IDENTITY)
    # unit_arc on directions already normalised gives the same turn to the last bits
    a, b = np.array([0.6, 0.0, 0.8]), np.array([0.0, 1.0, 0.0])
    np.testing.assert_allclose(quat.unit_arc(a, b), quat.shortest_arc(5 * a, 2 * b), atol=1e-15)

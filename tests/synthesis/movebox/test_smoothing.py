"""Exponential smoothing onto the display clock: the time constant it is given, the same
result however the ticks are split, and less jitter."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.synthesis.movebox.smoothing import ExponentialSmoother, smoothing_alpha


def test_step_response_reaches_one_minus_1_over_e_after_tau():
    rate, tau = 90.0, 1.0 / 30.0
    smoother = ExponentialSmoother(smoothing_alpha(rate, tau))
    steps = np.concatenate([np.zeros((1, 1)), np.ones((30, 1))])
    out = smoother("x", steps, rotation=False)[:, 0]
    at_tau = out[1 + int(round(tau * rate)) - 1]  # 3 ticks after the step
    assert abs(at_tau - (1 - np.exp(-1))) < 1e-9


def test_split_batches_equal_one_batch():
    rng = np.random.default_rng(0)
    q = quat.normalize(rng.normal(size=(40, 5, 4)))
    a = ExponentialSmoother(0.3)("q", q, rotation=True)
    s = ExponentialSmoother(0.3)
    b = np.concatenate([s("q", q[:7], True), s("q", q[7:8], True), s("q", q[8:], True)])
    assert np.allclose(a, b)


def test_smoothing_reduces_rotation_jitter():
    rng = np.random.default_rng(1)
    base = quat.from_axis_angle(np.array([0.0, 0, 1]), np.linspace(0, 1, 300))
    noisy = quat.normalize(base + rng.normal(scale=0.02, size=base.shape))
    smooth = ExponentialSmoother(smoothing_alpha(90.0))("q", noisy[:, None], True)[:, 0]

    def jitter(q):
        return np.std(np.diff(q, n=2, axis=0))

    # seeds 0-4: ratio 0.16-0.18
    assert jitter(smooth) < 0.3 * jitter(noisy)


def test_absolute_is_the_product_down_the_hierarchy_and_relative_undoes_it(box_truth):
    from avatarsim.synthesis.movebox.smoothing import absolute, relative

    local = box_truth.local_rot[:5]
    world = absolute(local, box_truth.skeleton.parents)
    # q_absolute (MoveBox §III-A1) is what forward kinematics composes
    assert np.allclose(np.abs(np.sum(world * box_truth.global_rotations()[:5], -1)), 1.0)
    assert np.allclose(relative(world, box_truth.skeleton.parents), local)

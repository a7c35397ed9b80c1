"""Finger IK on the controller's handle (eqs. 5-7): never inside by more than 2 mm, closed
onto it, within the joints' limits; the capsule SDF against its definition."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import sample_subject
from avatarsim.avatar_models.generator.subject import subject_skeleton
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.synthesis.avatargo.fingers import FingerIK, capsule_sdf, finger_points
from avatarsim.synthesis.avatargo.hands import CONTROLLER_RADIUS_M, grip_of


def test_capsule_sdf():
    s, e, r = np.zeros(3), np.array([0.1, 0.0, 0.0]), 0.02
    points = np.array([[0.05, 0.0, 0.05], [0.05, 0.0, 0.0], [-0.03, 0.0, 0.0], [0.14, 0.03, 0]])
    np.testing.assert_allclose(capsule_sdf(points, s, e, r), [0.03, -0.02, 0.01, 0.03], atol=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_fingers_close_onto_the_handle_without_entering(seed):
    """Avatar rig hands of random subjects (sizes 1.5-1.95 m): after the first solve and
    100 more frames every finger's closest point is within 2 mm outside/inside the handle's
    surface (measured on seeds 0-3: -0.000 to +0.005 mm), and none opens up again."""
    skeleton = subject_skeleton(sample_subject(np.random.default_rng(seed)))
    ik = FingerIK(skeleton, grip_of(skeleton))
    first = ik.advance().copy()
    for _ in range(100):
        t = ik.advance()
    closest = ik.sdf(t).min(-1)  # (10,) per finger
    assert closest.min() > -0.002
    assert closest.max() < 0.002
    assert (t >= 0).all() and (t <= 1).all()
    np.testing.assert_allclose(t, first, atol=0.05)


def test_thumb_button_pulls_the_thumb():
    skeleton = load_rig("avatar").skeleton
    grip = grip_of(skeleton)
    button = grip.handle.mean(1) + np.array([0.0, 0.0, -CONTROLLER_RADIUS_M])  # under it
    free, pressing = FingerIK(skeleton, grip), FingerIK(skeleton, grip, thumb_button=button)
    tips = [ik.sdf(ik.advance()) for ik in (free, pressing)]
    assert not np.allclose(pressing.t[[0, 5]], free.t[[0, 5]])
    assert tips[1].min() > -0.002
    # Each thumb tip ends nearer its button than the free thumb's: the pull's direction. The
    # handle's penalty holds the thumb almost open, so the pull gains little (69.26 mm free,
    # 69.11 mm pressing, deterministic), and a reversed pull would push it further away.
    gap = [np.linalg.norm(finger_points(ik.rig, ik.t)[::5, 2] - button, axis=-1) for ik in
           (free, pressing)]  # fmt: skip
    assert np.all(gap[1] < gap[0] - 5e-5), gap


def test_every_session_starts_with_the_hands_on_the_handle():
    """The first frame's solve is done once, at construction: after a reset, whatever the
    last session left (here a hand opened and three steps from open), the first frame again
    holds the first session's grip, every finger within 2 mm of the handle's surface."""
    skeleton = load_rig("avatar").skeleton
    ik = FingerIK(skeleton, grip_of(skeleton))
    first = ik.advance().copy()
    ik.reset()
    assert not ik.t.any()  # open hands
    ik.iterate(3)
    ik.reset()
    again = ik.advance()
    np.testing.assert_array_equal(again, first)
    assert np.abs(ik.sdf(again).min(-1)).max() < 0.002

"""The direction helpers of the two-bone solver: :func:`unit` and :func:`unit_arc`."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.synthesis.two_bone import unit, unit_arc


def test_unit_gives_directions_and_lengths():
    v = np.array([[3.0, 0.0, 4.0], [0.0, 0.0, 0.0]])
    directions, lengths = unit(v)
    np.testing.assert_allclose(directions, [[0.6, 0.0, 0.8], [0.0, 0.0, 0.0]])  # zero stays
    np.testing.assert_allclose(lengths, [5.0, 0.0])


def test_unit_arc_turns_one_direction_onto_the_other():
    rng = np.random.default_rng(0)
    a, _ = unit(rng.normal(size=(5, 3)))
    b, _ = unit(rng.normal(size=(5, 3)))
    q = unit_arc(a, b)
    np.testing.assert_allclose(quat.rotate(q, a), b, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0)
    # The smallest such turn: by the angle between the directions, about their normal.
    np.testing.assert_allclose(2 * np.arccos(q[:, 0]), np.arccos((a * b).sum(-1)), atol=1e-9)
    normal = np.cross(a, b)
    np.testing.assert_allclose(np.cross(q[:, 1:], normal), 0.0, atol=1e-12)
    # Opposite directions have no single shortest arc: identity.
    np.testing.assert_allclose(unit_arc(a[:1], -a[:1]), [quat.IDENTITY])

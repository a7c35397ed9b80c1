"""The direction helper of the two-bone solver, :func:`unit`."""

from __future__ import annotations

import numpy as np

from avatarsim.synthesis.two_bone import unit


def test_unit_gives_directions_and_lengths():
    v = np.array([[3.0, 0.0, 4.0], [0.0, 0.0, 0.0]])
    directions, lengths = unit(v)
    np.testing.assert_allclose(directions, [[0.6, 0.0, 0.8], [0.0, 0.0, 0.0]])  # zero stays
    np.testing.assert_allclose(lengths, [5.0, 0.0])

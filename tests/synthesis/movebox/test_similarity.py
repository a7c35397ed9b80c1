"""The §III similarity index and loop trimming: the true period of a periodic built-in
motion is found to within one frame."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import STYLES, Subject, generate
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.similarity import loop_points, similarity_index, similarity_matrix


def test_index_is_zero_for_equal_states_and_the_sum_of_half_angle_sines():
    rng = np.random.default_rng(0)
    a = quat.normalize(rng.normal(size=(6, 4)))
    assert similarity_index(a, a) == pytest.approx(0.0, abs=1e-12)
    b = quat.normalize(rng.normal(size=(6, 4)))
    # |vec(q1 q2^-1)| = sin(angle between them / 2), summed over joints (independent form)
    angle = quat.angle(quat.mul(a, quat.conj(b)))
    assert similarity_index(a, b) == pytest.approx(np.sin(angle / 2).sum())
    assert similarity_index(a, -b) == pytest.approx(similarity_index(a, b))


def test_matrix_equals_pairwise_index():
    rng = np.random.default_rng(1)
    a = quat.normalize(rng.normal(size=(5, 7, 4)))
    b = quat.normalize(rng.normal(size=(3, 7, 4)))
    pairs = similarity_index(a[:, None], b[None])
    assert np.allclose(similarity_matrix(a, b), pairs)


@pytest.mark.parametrize("seed", [0, 1])
def test_loop_trimmer_finds_the_squat_period(seed):
    subject = Subject()
    fps = 30.0
    # The generator's squat: depth follows cos(2 pi 0.4 tempo t) (exercises.py).
    period = fps / (0.4 * STYLES[subject.style].tempo)
    motion = generate("squat", subject, duration_s=4.0, fps=fps, seed=seed)
    start, stop = loop_points(motion.local_rot, search_frames=int(1.2 * fps))
    # seeds 0-4: 75 frames every time (period 75)
    assert abs((stop - start) - period) <= 1.0


def test_too_short_a_clip_has_no_loop():
    q = np.tile(quat.IDENTITY, (4, 3, 1))
    with pytest.raises(SynthesisError, match="no pair"):
        loop_points(q, search_frames=2, min_frames=10)

"""Scoring a run: errors by group and hand correlation on inputs with known answers, and the
one run-and-score path's row."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.coolmoves import CoolMoves
from avatarsim.synthesis.scoring import GROUPS, body17_errors_cm, hand_correlation, score_run
from tests.synthesis.conftest import TEST_SUBJECT, TruthReplay


def test_errors_by_group_on_a_known_offset():
    """Shifting the root by 3 cm up and 4 cm sideways moves every joint by 5 cm."""
    truth = generate("box", Subject(), 0.5, 90.0, seed=1)
    moved = truth.translated(np.array([0.0, 0.03, 0.04]))
    err = body17_errors_cm(moved, truth, skip=0)
    assert err == pytest.approx({"hands": 5.0, "upper": 5.0, "lower": 5.0, "full": 5.0})


def test_errors_only_over_the_frames_asked_for():
    """The second half shifted by 5 cm, the first exact: 5 cm over the second half alone,
    NaN over no frame."""
    truth = generate("box", Subject(), 0.5, 90.0, seed=1)
    half = truth.n_frames // 2
    second = truth.translated(np.array([0.0, 0.03, 0.04]))
    root = np.concatenate([truth.root_pos[:half], second.root_pos[half:]])
    output = Motion(truth.skeleton, truth.fps, root, truth.local_rot)
    late = np.arange(truth.n_frames) >= half
    assert body17_errors_cm(output, truth, frames=late)["full"] == pytest.approx(5.0)
    assert np.isnan(body17_errors_cm(output, truth, frames=np.zeros_like(late))["full"])


def test_a_perfect_method_scores_zero_error_and_full_correlation(test_motion):
    stream = VRSetup().sample(test_motion, seed=0)
    score = score_run(TruthReplay(test_motion), test_motion, stream, time_steps=True)
    assert score.err_cm == pytest.approx(dict.fromkeys(GROUPS, 0.0), abs=1e-9)
    assert score.hand_corr == pytest.approx({"left": 1.0, "right": 1.0}, abs=1e-6)
    row = score.row()
    assert row["frames"] == test_motion.n_frames and row["seconds"] > 0
    assert score.step_ms.shape == (stream.n_samples,) and row["step_ms_p99"] > 0


def test_hand_correlation_of_a_too_short_clip_is_a_clear_error(small_db, test_motion):
    short = test_motion[:6]  # shorter than the 9-sample window warm-up
    short_stream = VRSetup().sample(short, seed=0)
    output = CoolMoves(small_db, TEST_SUBJECT.height_m).run(short_stream)
    with pytest.raises(SynthesisError, match="at least 3 tracked frames"):
        hand_correlation(output, short_stream)

"""Folds never test on what the database holds; a class too small to split is skipped."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import generate
from avatarsim.synthesis.evaluate import EvaluationError, Trial, database_for, folds


def _trial(cls, subject, take, motion=None):
    return Trial(motion, cls, subject, take, f"{cls}_{subject}_{take}", 0)


LABELS = [_trial(c, s, k) for c in ("box", "run") for s in ("a", "b", "c") for k in (1, 2)]


def test_cross_subject_never_tests_on_a_database_subject():
    all_folds, skipped = folds(LABELS, "cross-subject")
    assert not skipped and len(all_folds) == 6  # 2 classes x 3 subjects
    for fold in all_folds:
        assert {t.subject for t in fold.test} == {fold.held_out}
        assert fold.held_out not in {t.subject for t in fold.train}
        assert {t.cls for t in fold.train + fold.test} == {fold.cls}
        assert len(fold.test) == 2 and len(fold.train) == 4


def test_cross_trial_holds_out_one_trial_and_keeps_the_subjects_other_takes():
    all_folds, _ = folds(LABELS, "cross-trial")
    assert len(all_folds) == 12
    for fold in all_folds:
        (test,) = fold.test
        assert all(t is not test for t in fold.train)
        assert any(t.subject == test.subject for t in fold.train)  # per-user calibration


def test_take_labels_without_subjects_split_by_take():
    bandai = [_trial("tired", None, k) for k in (1, 2, 3) for _ in range(2)]
    all_folds, _ = folds(bandai, "cross-trial")
    assert len(all_folds) == 3
    for fold in all_folds:
        assert {t.take for t in fold.test}.isdisjoint({t.take for t in fold.train})
    with pytest.raises(EvaluationError, match="no subject labels|none"):
        folds(bandai, "cross-subject")


def test_class_with_one_subject_is_skipped_with_a_reason():
    trials = [*LABELS, _trial("swim", "a", 1)]
    _, skipped = folds(trials, "cross-subject")
    assert "swim" in skipped and "at least 2" in skipped["swim"]
    with pytest.raises(EvaluationError, match="unknown protocol"):
        folds(trials, "cross-everything")


def test_turned_database_copies_keep_a_static_root_static():
    """The generated rig's root (``Bip01``) is a static node above the pelvis, which carries
    the heading: copies turned to other headings turn the pelvis too, so that every stored
    pose keeps one root rotation and blending local rotations never mixes two conventions."""
    walk = generate("walk", duration_s=1.0, fps=30.0)
    assert np.ptp(walk.local_rot[:, 0], axis=0).max() == 0.0
    database = database_for([_trial("walk", "a", 1, walk)], headings=4)
    roots = database.poses[:, 0]
    np.testing.assert_allclose(np.abs(quat.dot(roots, walk.local_rot[0, 0])), 1.0, atol=1e-12)
    # and the pelvis faces all four ways
    facing = quat.rotate(database.poses[:, 1], np.array([1.0, 0.0, 0.0]))
    yaws = np.degrees(np.arctan2(facing[:, 1], facing[:, 0]))
    for heading in (0.0, 90.0, 180.0, -90.0):
        assert np.any(np.abs((yaws - heading + 180.0) % 360.0 - 180.0) < 30.0)

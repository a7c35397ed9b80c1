"""Folds never test on what the database holds; a class too small to split is skipped."""

from __future__ import annotations

import pytest

from synthesis.evaluate import EvaluationError, Trial, folds


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

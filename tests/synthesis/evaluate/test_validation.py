"""The distance threshold is chosen on the fold's training data only."""

from __future__ import annotations

from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.coolmoves import Options
from avatarsim.synthesis.evaluate import builtin_trials, folds
from avatarsim.synthesis.evaluate.validation import (
    DISTANCE_GRID,
    choose_max_distance,
    validation_split,
)


def test_validation_split_holds_out_a_training_group():
    trials = builtin_trials(("box",), n_subjects=3, n_takes=1, duration_s=1.0, seed=5)
    fold = folds(trials, "cross-subject")[0][0]
    fit, held = validation_split(fold.train, "cross-subject")
    assert held and fit
    assert {t.subject for t in held}.isdisjoint({t.subject for t in fit})
    assert {t.name for t in fit} | {t.name for t in held} == {t.name for t in fold.train}
    assert {t.subject for t in fold.test}.isdisjoint({t.subject for t in fit + held})
    # One training group: nothing to validate on, the default stays.
    assert validation_split(fold.train[:1], "cross-subject")[1] == []


def test_choice_is_a_grid_value_and_ignores_the_test_trials():
    trials = builtin_trials(("box",), n_subjects=3, n_takes=1, duration_s=1.5, seed=5)
    fold = folds(trials, "cross-subject")[0][0]
    chosen = choose_max_distance(fold.train, "cross-subject", Options(), VRSetup())
    assert chosen in DISTANCE_GRID
    assert (
        choose_max_distance(fold.train[:1], "cross-subject", Options(), VRSetup())
        == Options().max_distance
    )

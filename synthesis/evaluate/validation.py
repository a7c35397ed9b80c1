"""Hyper-parameters chosen inside a fold's training data, never on its test trials.

The paper gives no value for the KD-tree's neighbourhood distance threshold (§3.1.3). It is
chosen per fold on a validation split of that fold's *training* trials: the last training
group (a subject cross-subject, a trial cross-trial) is held out, a database is built on the
others, and the grid value with the lowest mean full-body error on the held-out group wins.
The test fold is never seen. Everything else the paper fixes (90 Hz, 9-sample windows, k = 5,
the correlation threshold 0.1, the alignment's c_i, the EWMA weight) is not tuned.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.coolmoves import CoolMoves, Options
from avatarsim.synthesis.evaluate.folds import database_for, group_of
from avatarsim.synthesis.evaluate.trials import Trial
from avatarsim.synthesis.scoring import score_run

DISTANCE_GRID = (0.3, 0.6, 1.2)
"""Candidate thresholds, in the units of :mod:`synthesis.coolmoves.features` (metres over
one window's positions, velocities and accelerations): half, once and twice the default
:data:`synthesis.coolmoves.knn.MAX_DISTANCE` (0.6)."""


def validation_split(train: Sequence[Trial], protocol: str) -> tuple[list[Trial], list[Trial]]:
    """``(fit, held)``: the training trials without their last group, and that group
    (``held`` is empty when the training trials form fewer than two groups)."""
    groups = sorted({g for t in train if (g := group_of(t, protocol)) is not None})
    if len(groups) < 2:
        return list(train), []
    held = [t for t in train if group_of(t, protocol) == groups[-1]]
    return [t for t in train if group_of(t, protocol) != groups[-1]], held


def choose_max_distance(
    train: Sequence[Trial],
    protocol: str,
    options: Options,
    setup: VRSetup,
    grid: Sequence[float] = DISTANCE_GRID,
) -> float:
    """The grid threshold with the lowest mean full-body error on the validation split of
    ``train`` (:func:`validation_split`); ``options.max_distance`` when there is no split
    or its database cannot be built (e.g. no fit trial passes the correlation filter)."""
    fit, held = validation_split(train, protocol)
    if not held:
        return options.max_distance
    try:
        database = database_for(fit)
    except SynthesisError:
        return options.max_distance
    errors = np.zeros(len(grid))
    for trial in held:
        stream = setup.sample(trial.motion, seed=trial.seed)
        height = standing_height(trial.motion)
        for i, distance in enumerate(grid):
            synth = CoolMoves(database, height, replace(options, max_distance=float(distance)))
            errors[i] += score_run(synth, trial.motion, stream).err_cm["full"]
    return float(grid[int(np.argmin(errors))])

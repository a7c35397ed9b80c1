"""Paper-mode CoolMoves against the positions-only reference
(:mod:`tests.measurements.coolmoves_reference`), one difference at a time, on Bandai
dataset-2 cross-trial with classes by activity.

    PYTHONPATH=. .venv/bin/python -m tests.measurements.coolmoves_ablation [MOCAP_DIR] [CLASS...]

Per fold: the database of the training trials and the distance threshold chosen on their
validation split (:func:`synthesis.evaluate.validation.choose_max_distance`), as the protocol
does; the test trials are never used to choose anything. Prints, per variant, the mean over
classes of full-body and hand error (cm) and of the mean hand correlation, then the
full-body error per class, and the floor of any single-pose pick: the database pose nearest
to the truth (head-relative body17 joints, knowing the truth, no alignment), per frame
(:mod:`tests.measurements.coolmoves_floors` has the other floors). Variants marked
"diagnostic" or "beyond" are not the paper's method.

Measured (210 trials, 30 folds, one job: 18 min wall, 7 min CPU; the 2-heading row with the
same folds and thresholds):

    variant             full cm  hands cm  hand r
    paper                  3.80      4.36   0.897
    no-threshold           3.82      4.33   0.895   (every k nearest blended, weight ~1)
    no-limits              3.80      4.36   0.897   (the widened limits never bind here)
    no-smoothing           3.82      4.33   0.897   (EWMA weight 1)
    no-alignment           3.47      4.30   0.903   (the paper's ablation, §4.1.2)
    own-hand alignment     3.64      4.34   0.902   (each hand's matches fit on that hand)
    no-scaling             3.80      4.36   0.897   (one performer: the scale is 1 anyway)
    no-filter              3.33      3.35   0.909   (diagnostic: every training trial kept)
    2 headings             3.18      3.85   0.907   (beyond: ``--db-headings 2``, see below)
    reference w=0.5        3.75      4.28   0.882   (positions-only, EWMA weight 0.5)
    reference w=1          3.76      4.13   0.881
    single-pose floor      2.71      4.86

Full body per class (paper): raise-up-both-hands 2.81, raise-up-left-hand 1.83,
raise-up-right-hand 1.83, run 8.41, walk 4.85, walk-turn-left 3.89, walk-turn-right 3.79,
wave-both-hands 6.04, wave-left-hand 2.47, wave-right-hand 2.04 (floor: 2.23, 1.47, 1.22,
4.66, 3.51, 3.06, 3.10, 5.09, 1.47, 1.24).

Where the error is, beyond our aim of 2.5 cm full and 2.8 cm hands:

- The hand-foot filter (§3.1.2) keeps 6 of 14 training trials of wave-both-hands and 10 of
  raise-up-both-hands; its score follows where the hands are held more than how they move:
  elderly and feminine waves (wrists on average 15-20 cm below the headset point) score
  0.63-0.65, normal (2-8 cm above) 0.16-0.34, active, exhausted, masculine and youthful
  (6-19 cm above) -0.29 to 0.07 and are dropped. Keeping every trial: wave-both-hands
  6.04 -> 2.14 cm full (hands 11.7 -> 2.9), raise-up-both-hands 2.81 -> 2.00; all classes
  3.80 -> 3.33 full, 4.36 -> 3.35 hands.
- The heading: run and walk take 2 go the other way along X to takes 1 and 3 of every
  style; the features are head-relative, not turned with the head (§3.1.2), so take 2 finds
  other styles at its own heading: run take 2 14.8 cm full, walk take 2 8.9 cm (takes 1 and
  3: 5.2-5.3 and 2.7-2.9). The yaw-free single-pose floor would bring run 4.66 -> 3.02,
  walk 3.51 -> 1.94.
- The alignment (§3.1.4) costs 0.33 cm full here: a database holds the test trial's own
  heading (walks and runs go back and forth along X), so there is little to undo, and a
  match's yaw fits both hands of its database window, although the match was found for one
  hand only (raise-up-right-hand 1.83 vs 1.49 without, wave-right-hand 2.04 vs 1.52).
  Fitting each hand's matches on that hand only (``Options.align_own_hand``; §3.1.4's ``s``
  is "the feature vector from the MoCap database", and a feature vector holds one hand,
  §3.1.2) recovers half of it. Each with the filter off as well (same folds and
  thresholds, one-off run): own-hand alignment 3.17 / 3.27 / 0.914, no alignment
  3.04 / 3.26 / 0.915.
- The window grid (a pose every 44 ms) costs the floor 0.03-0.26 cm full body.
- ``--db-headings 2`` (every training trial also turned by 180 deg, beyond the paper) gives
  take 2 its own styles: run 8.41 -> 4.34, walk 4.85 -> 2.49 (the other classes within
  0.12 cm). The copies are turned at the pelvis
  (:func:`synthesis.evaluate.folds.database_for`): turned at Bandai's static root
  ``joint_Root``, a copy would differ from a recording facing the same way by 180 deg in the
  root and -180 deg in the hips, and blends of the two would turn the body anywhere.

Together (one-off runs, same folds and thresholds): filter off and 2 headings 2.71 / 2.83 /
0.919; with own-hand alignment too 2.61 / 2.77 / 0.925, the hands and hand r within our
aim, full body 0.11 cm above it: run 4.23, walk-turn-left 4.09, walk-turn-right
3.89 cm remain (their floors 4.66, 3.06, 3.10; yaw-free 3.02, 2.65, 2.65).

No single switch of the pipeline (threshold, limits, EWMA, scaling) moves full body by more than
0.04 cm, and the reference is within 0.05 cm full of paper mode.
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from avatarsim.avatar_models import body17
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import VRSetup
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.synthesis.coolmoves import CoolMoves
from avatarsim.synthesis.coolmoves.correlation import pearson
from avatarsim.synthesis.evaluate import database_for, folds, library_trials
from avatarsim.synthesis.evaluate.validation import choose_max_distance
from avatarsim.synthesis.methods import METHODS
from avatarsim.synthesis.scoring import GROUPS, WARM_UP, score_run
from tests.measurements import coolmoves_floors as floors
from tests.measurements import coolmoves_reference as reference

HANDS = body17.group_indices(body17.HANDS)


def reference_score(database, truth, stream, **kwargs) -> tuple[dict, float]:
    """Error per group (cm) and mean hand correlation (head-relative wrists vs controllers)
    of the reference on one trial."""
    out = reference.synthesize(database, stream, **kwargs)
    gt = body17_positions(motion_at_rate(truth, 90.0))
    n = min(len(out), len(gt))
    err = 100.0 * np.linalg.norm(out[:n] - gt[:n], axis=-1)[WARM_UP:].mean(axis=0)
    errs = {g: float(err[body17.group_indices(names)].mean()) for g, names in GROUPS.items()}
    head = body17.BODY17.index("head")
    given = gt[WARM_UP:n, HANDS] - gt[WARM_UP:n, head, None]
    produced = out[WARM_UP:n, HANDS] - out[WARM_UP:n, head, None]
    return errs, float(np.mean(pearson(given, produced, axis=0)))


def single_pose_floor(database, truth) -> tuple[dict, float]:
    """Error (cm) of the database pose nearest to the truth in head-relative body17 joints,
    per frame (no alignment, the truth known): what no pick of one database pose can beat
    (:mod:`tests.measurements.coolmoves_floors` has the other floors)."""
    err = floors.floor(floors.database_joints(database), floors.head_relative(truth))
    errs = {g: float(err[body17.group_indices(names)].mean()) for g, names in GROUPS.items()}
    return errs, float("nan")


DATABASES = {
    "paper": database_for,
    "no filter": lambda train: database_for(train, correlation_threshold=-np.inf),
    "2 headings": lambda train: database_for(train, headings=2),
}
"""The fold's database for a variant: the paper's, one keeping every training trial (the
hand-foot filter off, a diagnostic), one also holding every trial turned by 180 degrees
(beyond the paper: ``avatarsim eval --db-headings 2``)."""


def variants(options):
    """name -> (database, run): the :data:`DATABASES` key and
    ``run(database, height, truth, stream) -> (errors, hand r)``."""

    def coolmoves(**switches):
        def run(db, height, truth, stream):
            synth = CoolMoves(db, height, replace(options, **switches))
            score = score_run(synth, truth, stream)
            return score.err_cm, float(np.mean(list(score.hand_corr.values())))

        return run

    return {
        "paper": ("paper", coolmoves()),
        "no-threshold": ("paper", coolmoves(max_distance=1e9)),
        "no-limits": ("paper", coolmoves(clamp=False)),
        "no-smoothing": ("paper", coolmoves(smooth=False)),
        "no-alignment": ("paper", coolmoves(align=False)),
        "own-hand alignment": ("paper", coolmoves(align_own_hand=True)),
        "no-scaling": (
            "paper",
            lambda db, h, truth, stream: coolmoves()(
                db, standing_height(db.skeleton), truth, stream
            ),
        ),
        "no-filter": ("no filter", coolmoves()),
        "2 headings": ("2 headings", coolmoves()),
        "reference w=0.5": (
            "paper",
            lambda db, h, truth, stream: reference_score(db, truth, stream),
        ),
        "reference w=1": (
            "paper",
            lambda db, h, truth, stream: reference_score(db, truth, stream, ewma_weight=1.0),
        ),
        "single-pose floor": ("paper", lambda db, h, truth, stream: single_pose_floor(db, truth)),
    }


def main(folder: str, classes: list[str] | None) -> None:
    trials = library_trials(f"{folder}/bandai/dataset-2", class_by="activity", classes=classes)
    all_folds, _ = folds(trials, "cross-trial")
    setup, options = VRSetup(), METHODS["coolmoves"].options
    rows: dict[str, dict[str, list]] = {}
    for fold in all_folds:
        chosen = choose_max_distance(fold.train, fold.protocol, options, setup)
        runs = variants(replace(options, max_distance=chosen))
        databases = {name: DATABASES[name](fold.train) for name in {db for db, _ in runs.values()}}
        for trial in fold.test:
            stream = setup.sample(trial.motion, seed=trial.seed)
            height = standing_height(trial.motion)
            for name, (db, run) in runs.items():
                err, r = run(databases[db], height, trial.motion, stream)
                rows.setdefault(name, {}).setdefault(trial.cls, []).append(
                    (err["full"], err["hands"], r)
                )
        print(f"{fold.cls} / {fold.held_out}: threshold {chosen}", flush=True)
    floors.print_class_means(rows, ("variant", "full cm", "hands cm", "hand r"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "../shared/mocap", sys.argv[2:] or None)

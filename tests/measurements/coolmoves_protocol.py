"""Paper-mode CoolMoves on the same Bandai dataset-2 test clips under three databases
(is the gap to a leave-one-clip-out reimplementation the protocol?).

    PYTHONPATH=. .venv/bin/python -m tests.measurements.coolmoves_protocol [MOCAP_DIR] [STYLE...]

Test clips: take 1 of every activity in the given styles (default ``normal``). Databases:

- ``cross-trial``: the protocol of the evaluation, cross-trial by activity: the test clip's
  activity, takes 2 and 3 (14 clips, every style);
- ``take-out``: every activity and style, takes 2 and 3 (140 clips);
- ``clip-out``: leave one clip out over the whole library: the 209 other clips, the test
  clip's own take of other activities and styles included.

Everything but the database is fixed: the default threshold (nothing is chosen, so no test
clip is seen), paper mode, and the positions-only reference and the single-pose floor of
:mod:`tests.measurements.coolmoves_ablation` beside it. Prints per database the mean over
test clips of full-body and hand error (cm) and mean hand correlation.

Measured (threshold 0.6; take 1 of the 10 activities; full cm /
hands cm / hand r). Style normal (10 clips):

    database     paper               no threshold        reference w=0.5     single-pose floor
    cross-trial  2.50 / 2.65 / 0.916 2.56 / 2.67 / 0.910 2.56 / 2.77 / 0.915 1.81 / 3.02
    take-out     2.75 / 2.79 / 0.915 2.79 / 2.81 / 0.909 2.77 / 2.82 / 0.917 1.77 / 2.97
    clip-out     2.88 / 2.87 / 0.907 2.92 / 2.89 / 0.900 2.89 / 2.87 / 0.912 1.74 / 2.92

Styles exhausted and active (20 clips):

    cross-trial  4.77 / 5.64 / 0.884 4.75 / 5.46 / 0.883 4.77 / 5.35 / 0.890 3.61 / 6.02
    take-out     4.66 / 5.30 / 0.894 4.69 / 5.21 / 0.890 4.57 / 4.13 / 0.896 3.04 / 5.22
    clip-out     4.70 / 5.42 / 0.886 4.74 / 5.34 / 0.884 4.60 / 4.16 / 0.895 2.97 / 5.10

Over the 30 clips, paper mode is about as good under either protocol (cross-trial 4.01 /
4.64 / 0.895, clip-out 4.09 / 4.57 / 0.893): the whole library lowers the floor (a nearer
pose exists) but the search by hand windows does not find it (normal run 5.6 -> 8.4 cm;
exhausted/active gain 0.07 cm). What the protocol changes is the positions-only reference's
hands: beside paper mode they are 0.15 cm better cross-trial (4.49) and 0.84 cm better
leave-one-clip-out (3.73; 1.26 cm on exhausted/active), with full body within 0.06 cm and
hand r within 0.01. So a positions-only reimplementation doing "markedly better" on a
leave-one-clip-out protocol fits these numbers for the hands only: blending matched joint
positions instead of joint rotations (§3.1.4 says "interpolate between" the poses; its joint
angle thresholds and bone scaling read as a rotation skeleton) matters once the k matches
come from many clips of other activities and styles.
"""

from __future__ import annotations

import sys
import time
from functools import cache

import numpy as np

from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.evaluate import database_for, library_trials
from avatarsim.synthesis.methods import METHODS
from tests.measurements.coolmoves_ablation import variants

SHOWN = ("paper", "no-threshold", "reference w=0.5", "single-pose floor")
"""The :func:`~tests.measurements.coolmoves_ablation.variants` run under every database."""


def main(folder: str, styles: list[str]) -> None:
    trials = library_trials(f"{folder}/bandai/dataset-2", class_by="activity")
    test = [t for t in trials if t.take == 1 and any(f"_{s}_" in t.name for s in styles)]
    runs = {k: v for k, v in variants(METHODS["coolmoves"].options).items() if k in SHOWN}
    take_out = cache(lambda: database_for([t for t in trials if t.take != 1]))
    per_activity = cache(
        lambda cls: database_for([t for t in trials if t.cls == cls and t.take != 1])
    )
    databases = {
        "cross-trial": lambda trial: per_activity(trial.cls),
        "take-out": lambda trial: take_out(),
        "clip-out": lambda trial: database_for([t for t in trials if t is not trial]),
    }
    rows: dict[tuple[str, str], list] = {}
    for trial in test:
        stream = VRSetup().sample(trial.motion, seed=trial.seed)
        height = standing_height(trial.motion)
        for db_name, database_of in databases.items():
            start = time.perf_counter()
            database = database_of(trial)
            built = time.perf_counter() - start
            for name, run in runs.items():
                err, r = run(database, height, trial.motion, stream)
                rows.setdefault((db_name, name), []).append((err["full"], err["hands"], r))
            full = rows[(db_name, "paper")][-1][0]
            print(f"{trial.name} {db_name}: paper {full:.2f} cm (db {built:.0f} s)", flush=True)
    print(f"{len(test)} test clips; {'database':12s} {'variant':18s} full cm  hands cm  hand r")
    for (db_name, name), values in rows.items():
        mean = np.mean(values, axis=0)
        print(f"{db_name:12s} {name:18s} {mean[0]:7.2f} {mean[1]:9.2f} {mean[2]:7.3f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "../shared/mocap", sys.argv[2:] or ["normal"])

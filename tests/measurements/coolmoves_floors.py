"""Floors of any single-pose pick for CoolMoves on Bandai dataset-2, cross-trial by activity:
per test frame, the training pose nearest to the truth, knowing the truth.

    PYTHONPATH=. .venv/bin/python -m tests.measurements.coolmoves_floors [MOCAP_DIR] [TAKE]

Per fold (only those holding out ``TAKE``, e.g. ``None/1``; all 30 without it), head-relative
``body17`` joints (minus the headset point), nearest in Euclidean distance over all 17 joints
("body") or over the two wrists only ("wrists"), from:

- ``ends``: the database's poses (window ends, every 4th 90 Hz frame, trials that pass the
  hand-foot filter): what the method can pick from;
- ``every``: every 90 Hz frame of every training trial, filter or not;

each either as stored ("as is") or with both sides turned to face +X first ("yaw-free": the
heading from the hip line; the pick is turned back to the truth's heading). Prints the mean
over classes of full-body and hand error (cm), then per class.

Measured (210 trials, 30 folds; ``ends as is body`` is the ablation's
single-pose floor):

    floor                      full cm  hands cm
    ends   as is    body          2.71      4.86
    ends   as is    wrists        3.98      3.73
    ends   yaw-free body          2.30      4.01
    ends   yaw-free wrists        3.30      3.21
    every  as is    body          2.20      3.77
    every  as is    wrists        3.53      2.58
    every  yaw-free body          1.78      2.89
    every  yaw-free wrists        2.84      2.03

Full-body ``ends as is body`` per class: raise-up-both-hands 2.23, raise-up-left-hand 1.47,
raise-up-right-hand 1.22, run 4.66, walk 3.51, walk-turn-left 3.06, walk-turn-right 3.10,
wave-both-hands 5.09, wave-left-hand 1.47, wave-right-hand 1.24.

What moves it, largest first:

- the hand-foot filter (§3.1.2): it keeps 6 of the 14 training trials of wave-both-hands
  (10 of raise-up-both-hands; every trial of the other classes). ``every`` frame of every
  trial brings wave-both-hands from 5.09 to 1.48 cm, raise-up-both-hands from 2.23 to 1.51;
- the heading: run and walk take 2 go the opposite way to takes 1 and 3 of each style, and
  the features are not turned with the head (§3.1.2). Yaw-free brings run from 4.66 to 3.02,
  walk from 3.51 to 1.94 (take 2 alone: run 7.07 -> 2.85, walk 6.14 -> 1.95);
- least, the window grid (a pose every 4th 90 Hz frame, 44 ms): on the eight classes whose
  trials all pass the filter, ``every`` frame instead of the window ends gains 0.03-0.26 cm
  full body (the largest, run); on the folds holding out take 1, 0.1-0.3 cm on the hands.
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.spatial import cKDTree

from avatarsim.avatar_models import Motion, body17
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.synthesis.coolmoves import Database
from avatarsim.synthesis.coolmoves.database import HANDS_DRIVE, driver_positions
from avatarsim.synthesis.evaluate import database_for, folds, library_trials
from avatarsim.synthesis.scoring import WARM_UP

HANDS = body17.group_indices(body17.HANDS)
HIPS = [body17.BODY17.index(j) for j in ("l_hip", "r_hip")]
SELECTIONS = {"body": slice(None), "wrists": HANDS}


def head_relative(motion: Motion) -> np.ndarray:
    """``(T, 17, 3)`` body17 joints of ``motion`` at 90 Hz minus its headset point."""
    motion = motion_at_rate(motion, 90.0)
    head, _ = driver_positions(motion, HANDS_DRIVE)
    return body17_positions(motion) - head[:, None]


def database_joints(database: Database) -> np.ndarray:
    """``(P, 17, 3)`` head-relative body17 joints of every database pose."""
    poses = database.poses
    return head_relative(Motion(database.skeleton, 90.0, np.zeros((len(poses), 3)), poses))


def heading(joints: np.ndarray) -> np.ndarray:
    """``(T,)`` yaw (radians) of the facing direction: the hip line (left minus right) turned
    90 degrees clockwise about +Z."""
    across = joints[:, HIPS[0]] - joints[:, HIPS[1]]
    return np.arctan2(across[:, 1], across[:, 0]) - 0.5 * np.pi


def turned(joints: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """``joints (T, J, 3)`` turned by ``yaw (T,)`` about +Z."""
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x, y = joints[..., 0], joints[..., 1]
    return np.stack([c * x - s * y, s * x + c * y, joints[..., 2]], axis=-1)


def floor(
    candidates: np.ndarray, truth: np.ndarray, on: str = "body", yaw_free: bool = False
) -> np.ndarray:
    """``(17,)`` mean error (cm) per joint of the candidate ``(P, 17, 3)`` nearest to each
    truth frame ``(T, 17, 3)`` in the joints ``on`` (:data:`SELECTIONS`), after the warm-up."""
    if yaw_free:
        facing = heading(truth)
        candidates, query = turned(candidates, -heading(candidates)), turned(truth, -facing)
    else:
        query = truth
    sel = SELECTIONS[on]
    _, nearest = cKDTree(candidates[:, sel].reshape(len(candidates), -1)).query(
        query[:, sel].reshape(len(query), -1)
    )
    pick = turned(candidates[nearest], facing) if yaw_free else candidates[nearest]
    return 100.0 * np.linalg.norm(pick - truth, axis=-1)[WARM_UP:].mean(axis=0)


def main(folder: str, take: str | None) -> None:
    trials = library_trials(f"{folder}/bandai/dataset-2", class_by="activity")
    rows: dict[str, dict[str, list]] = {}
    for fold in folds(trials, "cross-trial")[0]:
        if take is not None and fold.held_out != take:
            continue
        pools = {
            "ends": database_joints(database_for(fold.train)),
            "every": np.concatenate([head_relative(t.motion) for t in fold.train]),
        }
        for trial in fold.test:
            truth = head_relative(trial.motion)
            for pool, candidates in pools.items():
                for yaw_free in (False, True):
                    for on in SELECTIONS:
                        err = floor(candidates, truth, on, yaw_free)
                        key = f"{pool} {'yaw-free' if yaw_free else 'as is'} {on}"
                        rows.setdefault(key, {}).setdefault(fold.cls, []).append(
                            (err.mean(), err[HANDS].mean())
                        )
        print(f"{fold.cls} / {fold.held_out}", flush=True)
    print_class_means(rows, ("floor", "full cm", "hands cm"))


def print_class_means(rows: dict[str, dict[str, list]], header: tuple[str, ...]) -> None:
    """Print, per row name, the mean over classes of the per-class mean of its tuples
    (``rows[name][class]`` a list of tuples, one per trial, as many values as ``header``
    has columns after the name), then the first value per class."""
    print(f"{header[0]:26s} " + " ".join(f"{h:>8s}" for h in header[1:]))
    for name, per_class in rows.items():
        mean = np.mean([np.mean(v, axis=0) for v in per_class.values()], axis=0)
        print(f"{name:26s} " + " ".join(f"{m:8.3f}" for m in mean))
    for name, per_class in rows.items():
        cells = ", ".join(f"{c} {np.mean(v, axis=0)[0]:.2f}" for c, v in per_class.items())
        print(f"{name}: {header[1]} per class: {cells}")


if __name__ == "__main__":
    main(
        sys.argv[1] if len(sys.argv) > 1 else "../shared/mocap",
        sys.argv[2] if len(sys.argv) > 2 else None,
    )

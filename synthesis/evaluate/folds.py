"""Folds of the accuracy protocols (:data:`PROTOCOLS`) and the database of a fold.

``cross-subject`` holds out every trial of one subject of a class, the database holds the
class's other subjects; ``cross-trial`` holds out one trial (subject, take) and the database
holds the rest of the class. A class with fewer than two groups is skipped with the reason;
a source without any subject label cannot be evaluated cross-subject at all
(:class:`~synthesis.evaluate.trials.EvaluationError`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Skeleton
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.synthesis.coolmoves import Database, build_database, correlation
from avatarsim.synthesis.evaluate.trials import EvaluationError, Trial

PROTOCOLS = ("cross-subject", "cross-trial")


@dataclass(frozen=True, eq=False)
class Fold:
    """One leave-one-group-out fold of one class: the held-out group, train and test trials,
    and the protocol whose groups they are."""

    cls: str
    held_out: str
    train: list[Trial]
    test: list[Trial]
    protocol: str = "cross-trial"


def group_of(trial: Trial, protocol: str) -> str | None:
    """The group ``trial`` is held out with under ``protocol`` (its subject, or its trial)."""
    if protocol == "cross-subject":
        return trial.subject
    return f"{trial.subject}/{trial.take}" if trial.take is not None else trial.name


def folds(trials: Sequence[Trial], protocol: str) -> tuple[list[Fold], dict[str, str]]:
    """The folds of ``protocol`` per class, and ``{class: reason}`` for classes skipped.

    Raises :class:`EvaluationError` for an unknown protocol, or cross-subject on trials
    that carry no subject label at all (e.g. Bandai, whose actor is not labelled per file).
    """
    if protocol not in PROTOCOLS:
        raise EvaluationError(f"unknown protocol {protocol!r}; use {' or '.join(PROTOCOLS)}")
    if protocol == "cross-subject" and not any(t.subject is not None for t in trials):
        raise EvaluationError(
            "cross-subject needs subject labels and these clips have none (Bandai does not "
            "label its actors); use --protocol cross-trial"
        )
    out, skipped = [], {}
    for cls in sorted({t.cls for t in trials}):
        members = [t for t in trials if t.cls == cls]
        groups = sorted({g for t in members if (g := group_of(t, protocol)) is not None})
        if len(groups) < 2:
            label = "subjects" if protocol == "cross-subject" else "trials"
            skipped[cls] = f"{len(groups)} {label}; {protocol} needs at least 2"
            continue
        for held in groups:
            test = [t for t in members if group_of(t, protocol) == held]
            train = [t for t in members if group_of(t, protocol) != held]
            out.append(Fold(cls, held, train, test, protocol))
    return out, skipped


def heading_joint(skeleton: Skeleton) -> int:
    """Index of the joint that carries a body's heading: its pelvis (the ``body17`` map),
    the root on most rigs, the hips below Bandai's static ``joint_Root``."""
    return skeleton.index(identify_rig(skeleton).body17["pelvis"])


def database_for(
    train: Sequence[Trial],
    headings: int = 1,
    correlation_threshold: float = correlation.CORRELATION_THRESHOLD,
) -> Database:
    """The fold's database; ``headings > 1`` also holds every training motion turned to
    ``headings`` equally spaced yaws about Z; ``correlation_threshold`` is the hand-foot
    filter's (§3.1.2; ``-inf`` keeps every trial, a diagnostic).

    Beyond the paper: its features are head-relative but not turned with the head (§3.1.2),
    so a user facing away from every performer finds no window within the KD-tree threshold
    and the alignment (which only turns found matches) has nothing to work on. Turned copies
    give the search a match within ``180 / headings`` degrees, which the alignment refines.
    The copies are turned at the pelvis (:meth:`Motion.rotated_about_z`'s ``carrier``), the
    joint that carries the heading of every recorded pose: turned at a static reference root
    above it (Bandai's), a copy and a recording facing the same way would differ by 180 deg
    in two joints, and blending their local rotations would turn the body anywhere (Bandai
    run and walk, 2 headings: 18.0 and 12.4 cm full body, against 8.4 and 4.9 with none).
    """
    yaws = 2.0 * np.pi * np.arange(headings) / headings
    motions = [
        t.motion.rotated_about_z(float(a), carrier=heading_joint(t.motion.skeleton))
        for t in train
        for a in yaws
    ]
    return build_database(motions, correlation_threshold=correlation_threshold)

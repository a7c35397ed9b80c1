"""Trials of the accuracy protocols: ground-truth motions labelled with their class.

Sources: the built-in generator (:func:`builtin_trials`, the paper's Table 1 activities), or a
mocap folder (:func:`library_trials`; Bandai: style as class, take as trial, no subject
labels; CMU: activities from ``CLIPS.md``). Heading: every generated performer faces +X, so
alignment has nothing to correct there; :func:`turned` turns a test motion by a random yaw,
as users and CMU performers face any way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.generator import Subject, generate, sample_subject
from avatarsim.avatar_models.library import MotionLibrary
from avatarsim.synthesis.base import SynthesisError

PAPER_ACTIVITIES = ("box", "dribble", "climb_ladder", "run", "swim")
"""The generator's counterparts of the paper's Table 1 (boxing, basketball, climbing a ladder,
running, swimming)."""
TAKE_VARIATION = 0.15
"""Built-in takes: each take scales its subject's tempo and amplitude by a factor drawn
uniformly in ``1 +- TAKE_VARIATION``, so that two takes of one subject differ in speed and
range as repeated mocap trials do (else they differ only in start phase and seed, and
cross-trial would find the test take's own poses in the database)."""


class EvaluationError(SynthesisError):
    """The protocol cannot run on this source (no clips, no labels it needs)."""


@dataclass(frozen=True, eq=False)
class Trial:
    """One ground-truth motion and its labels; ``seed`` drives its simulated devices."""

    motion: Motion
    cls: str
    subject: str | None
    take: int | None
    name: str
    seed: int


def builtin_trials(
    activities: Sequence[str] = PAPER_ACTIVITIES,
    n_subjects: int = 5,
    n_takes: int = 2,
    duration_s: float = 8.0,
    seed: int = 0,
    take_variation: float = TAKE_VARIATION,
) -> list[Trial]:
    """Generated trials: ``n_subjects`` sampled subjects x ``activities`` x ``n_takes``; each
    take varies its subject's tempo and amplitude by ``1 +- take_variation``."""
    rng = np.random.default_rng(seed)
    subjects = [sample_subject(rng) for _ in range(n_subjects)]
    seeds = rng.integers(0, 2**31 - 1, size=(len(activities), n_subjects, n_takes))
    factors = rng.uniform(1 - take_variation, 1 + take_variation, (*seeds.shape, 2))

    def take_of(subject: Subject, f: np.ndarray) -> Subject:
        tempo, amplitude = np.clip([subject.tempo * f[0], subject.amplitude * f[1]], 0.5, 1.5)
        return replace(subject, tempo=float(tempo), amplitude=float(amplitude))

    return [
        Trial(
            generate(
                activity,
                take_of(subject, factors[a, s, k]),
                duration_s,
                90.0,
                int(seeds[a, s, k]),
            ),
            activity,
            str(s),
            k + 1,
            f"{activity}_s{s}_t{k + 1}",
            int(seeds[a, s, k]),
        )
        for a, activity in enumerate(activities)
        for s, subject in enumerate(subjects)
        for k in range(n_takes)
    ]


def library_trials(
    folder: str | Path,
    class_by: str | None = None,
    classes: Sequence[str] | None = None,
    max_per_class: int | None = None,
    seed: int = 0,
) -> list[Trial]:
    """Trials from a mocap folder indexed by :class:`MotionLibrary`.

    Args:
        class_by: ``"activity"`` or ``"style"``; default: style for Bandai (its styles are
            the stylised classes), activity otherwise.
        classes: keep only these classes.
        max_per_class: keep at most this many clips per class, the first by take then name
            (so whole takes survive); None keeps all.
    """
    library = MotionLibrary.index(folder)
    if len(library) == 0:
        raise EvaluationError(f"no motion clips under {folder}")
    if class_by is None:
        bandai = all(str(c.source or "").startswith("bandai") for c in library)
        class_by = "style" if bandai else "activity"
    if class_by not in ("activity", "style"):
        raise EvaluationError(f"classes are 'activity' or 'style', not {class_by!r}")
    groups = library.group_by(class_by)
    if classes is not None:
        groups = {k: v for k, v in groups.items() if k in set(classes)}
    if not groups:
        raise EvaluationError(
            f"no clip in {folder} has a label for {class_by}{' in ' if classes else ''}"
            f"{', '.join(classes) if classes else ''}"
        )
    rng = np.random.default_rng(seed)
    trials = []
    for cls, clips in groups.items():
        clips = sorted(clips, key=lambda c: (c.take or 0, c.name))[:max_per_class]
        for clip in clips:
            trials.append(
                Trial(
                    clip.load(),
                    str(cls),
                    clip.subject,
                    clip.take,
                    clip.name,
                    int(rng.integers(0, 2**31 - 1)),
                )
            )
    return trials


def turned(trial: Trial, heading_deg: float) -> Motion:
    """The trial's motion turned about Z by a yaw drawn uniformly in ``+-heading_deg`` (from
    the trial's seed): the user facing another way than the database's performers."""
    if heading_deg == 0:
        return trial.motion
    yaw = np.random.default_rng([trial.seed, 2]).uniform(-1.0, 1.0) * np.radians(heading_deg)
    return trial.motion.rotated_about_z(float(yaw))

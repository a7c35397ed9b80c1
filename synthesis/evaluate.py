"""CoolMoves' accuracy evaluation (§4.1): cross-subject and cross-trial protocols per class,
with the IK baseline side by side, hand correlation, the ablation and throughput.

- Trials: one ground-truth motion each, labelled with its class (the activity; a Bandai style),
  subject and take. Sources: the built-in generator (:func:`builtin_trials`, the paper's
  Table 1 activities), or a mocap folder (:func:`library_trials`; Bandai: style as class, take
  as trial, no subject labels; CMU: activities from ``CLIPS.md``).
- Protocols (:func:`folds`): ``cross-subject`` holds out every trial of one subject of a class,
  the database holds the class's other subjects; ``cross-trial`` holds out one trial
  (subject, take) and the database holds the rest of the class. A class with fewer than two
  groups is skipped with the reason in ``skipped``; a source without any subject label cannot
  be evaluated cross-subject at all (:class:`EvaluationError`).
- Per test trial: the headset and controllers are simulated (:class:`~render_cams.VRSetup`,
  the trial's seed), the method, its ablation variants and the IK baseline run on the same
  stream, errors and hand correlations are measured by :mod:`.coolmoves.accuracy`, and
  ``frames_per_s`` is the batch ``run`` throughput.
- Aggregation: a class's numbers are means over its test trials; ``overall`` is the mean over
  classes (each class counts once, as the paper averages over activities).
- Heading: every generated performer faces +X, so alignment has nothing to correct there.
  ``heading_deg`` turns each test motion by a random yaw (:func:`turned`), as users and CMU
  performers face any way; ``db_headings`` adds turned copies to the database
  (:func:`database_for`, beyond the paper).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from avatar_models import Motion
from avatar_models.body import BodyError
from avatar_models.generator import Subject, generate, sample_subject
from avatar_models.library import MotionLibrary
from avatar_models.measure import standing_height
from avatar_models.rigs import load_rig
from render_cams import TrackingStream, VRSetup
from synthesis.base import SynthesisError, Synthesizer
from synthesis.coolmoves import CoolMoves, Database, Options, build_database
from synthesis.coolmoves.accuracy import PAPER_ACTIVITIES, body17_errors_cm, hand_correlation
from synthesis.ik_baseline import IKBaseline

PROTOCOLS = ("cross-subject", "cross-trial")
METHODS: dict[str, Options] = {
    "coolmoves": Options(),
    "coolmoves-gmm": Options(matcher="gmm"),
    "coolmoves-centroid-align": Options(align_about_centroid=True),
}
"""Evaluable methods and their options (the GMM variant is the paper's slower alternative;
``coolmoves-centroid-align`` aligns with the paper's printed equation, see
:mod:`synthesis.coolmoves.alignment`)."""
TAKE_VARIATION = 0.15
"""Built-in takes: each take scales its subject's tempo and amplitude by a factor drawn
uniformly in ``1 +- TAKE_VARIATION``, so that two takes of one subject differ in speed and
range as repeated mocap trials do (else they differ only in start phase and seed, and
cross-trial would find the test take's own poses in the database)."""
ABLATION: dict[str, dict[str, bool]] = {
    "no_alignment_no_smoothing": {"align": False, "smooth": False},
    "alignment_no_smoothing": {"align": True, "smooth": False},
    "full": {"align": True, "smooth": True},
}
"""The paper's ablation steps (16.5 -> 13.2 -> 11.4 cm cross-subject, full body)."""
PAPER = {
    "err_cm": {
        "cross-subject": {"full": 11.4, "hands_left": 1.6, "hands_right": 1.9},
        "cross-trial": {"full": 9.6, "hands_left": 1.4, "hands_right": 1.7},
    },
    "baseline_err_cm": {"full": 12.1, "lower_minus_method": 3.5},
    "hand_corr": {"left": 0.92, "right": 0.94},
    "ablation_full_cm": [16.5, 13.2, 11.4],
    "gmm_full_cm": 10.6,
}
"""CoolMoves §4.1.2 numbers, for the report beside ours."""
GROUPS = ("hands", "upper", "lower", "full")


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
            f"no clip in {folder} has a {class_by} label{' in ' if classes else ''}"
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


@dataclass(frozen=True, eq=False)
class Fold:
    """One leave-one-group-out fold of one class: the held-out group, train and test trials."""

    cls: str
    held_out: str
    train: list[Trial]
    test: list[Trial]


def _group(trial: Trial, protocol: str) -> str | None:
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
        groups = sorted({g for t in members if (g := _group(t, protocol)) is not None})
        if len(groups) < 2:
            label = "subjects" if protocol == "cross-subject" else "trials"
            skipped[cls] = f"{len(groups)} {label}; {protocol} needs at least 2"
            continue
        for held in groups:
            test = [t for t in members if _group(t, protocol) == held]
            train = [t for t in members if _group(t, protocol) != held]
            out.append(Fold(cls, held, train, test))
    return out, skipped


def ik_baseline_for(database: Database, truth: Motion, setup: VRSetup) -> IKBaseline:
    """The IK baseline on the database's rig (the method's output rig); a rig whose rest pose
    does not stand (Bandai's) falls back to the avatar rig, calibrated with the true device
    offsets (positions only, its joint frames differ)."""
    height = standing_height(truth)
    try:
        return IKBaseline(database.skeleton, height)
    except BodyError:
        calibration = setup.attachments(truth, np.random.default_rng(0))
        return IKBaseline(load_rig("avatar").skeleton, height, calibration, False)


def _score(synth: Synthesizer, truth: Motion, stream: TrackingStream) -> dict:
    start = time.perf_counter()
    output = synth.run(stream)
    elapsed = time.perf_counter() - start
    return {
        "err_cm": body17_errors_cm(output, truth),
        "hand_corr": hand_correlation(output, stream),
        "frames": output.n_frames,
        "seconds": elapsed,
    }


def turned(trial: Trial, heading_deg: float) -> Motion:
    """The trial's motion turned about Z by a yaw drawn uniformly in ``+-heading_deg`` (from
    the trial's seed): the user facing another way than the database's performers."""
    if heading_deg == 0:
        return trial.motion
    yaw = np.random.default_rng([trial.seed, 2]).uniform(-1.0, 1.0) * np.radians(heading_deg)
    return trial.motion.rotated_about_z(float(yaw))


def database_for(train: Sequence[Trial], headings: int = 1) -> Database:
    """The fold's database; ``headings > 1`` also holds every training motion turned to
    ``headings`` equally spaced yaws about Z.

    Beyond the paper: its features are head-relative but not turned with the head (§3.1.2),
    so a user facing away from every performer finds no window within the KD-tree threshold
    and the alignment (which only turns found matches) has nothing to work on. Turned copies
    give the search a match within ``180 / headings`` degrees, which the alignment refines.
    """
    yaws = 2.0 * np.pi * np.arange(headings) / headings
    return build_database([t.motion.rotated_about_z(float(a)) for t in train for a in yaws])


def evaluate_fold(
    fold: Fold,
    options: Options,
    setup: VRSetup,
    ablation: bool = True,
    baseline_cache: dict | None = None,
    heading_deg: float = 0.0,
    db_headings: int = 1,
) -> list[dict]:
    """Per test trial of ``fold``: the method, its ablation variants and the IK baseline.

    ``heading_deg``: turn each test motion by a random yaw up to this (:func:`turned`);
    ``db_headings``: turned copies of the database (:func:`database_for`).
    """
    database = database_for(fold.train, db_headings)
    cache = {} if baseline_cache is None else baseline_cache
    rows = []
    for trial in fold.test:
        truth = turned(trial, heading_deg)
        stream = setup.sample(truth, seed=trial.seed)
        height = standing_height(truth)
        row = {"trial": trial.name, "cls": trial.cls, "held_out": fold.held_out}
        row["method"] = _score(CoolMoves(database, height, options), truth, stream)
        if ablation:
            row["ablation"] = {
                name: _score(
                    CoolMoves(database, height, replace(options, **switches)),
                    truth,
                    stream,
                )["err_cm"]["full"]
                for name, switches in ABLATION.items()
                if name != "full"
            }
            row["ablation"]["full"] = row["method"]["err_cm"]["full"]
        # The baseline does not use the database: one run per trial serves every fold.
        if trial.name not in cache:
            cache[trial.name] = _score(ik_baseline_for(database, truth, setup), truth, stream)
        row["baseline"] = cache[trial.name]
        rows.append(row)
    return rows


def summarise(rows: Sequence[dict]) -> dict:
    """Contract keys of a set of trial rows: means of errors and correlations, throughput."""

    def mean(path: Callable[[dict], float]) -> float:
        return float(np.mean([path(r) for r in rows]))

    def rate(key: str) -> float:
        return float(sum(r[key]["frames"] for r in rows) / sum(r[key]["seconds"] for r in rows))

    out = {
        "err_cm": {g: mean(lambda r, g=g: r["method"]["err_cm"][g]) for g in GROUPS},
        "baseline_err_cm": {g: mean(lambda r, g=g: r["baseline"]["err_cm"][g]) for g in GROUPS},
        "hand_corr": {
            s: mean(lambda r, s=s: r["method"]["hand_corr"][s]) for s in ("left", "right")
        },
        "baseline_hand_corr": {
            s: mean(lambda r, s=s: r["baseline"]["hand_corr"][s]) for s in ("left", "right")
        },
        "frames_per_s": rate("method"),
        "baseline_frames_per_s": rate("baseline"),
        "trials": len(rows),
    }
    if all("ablation" in r for r in rows):
        out["ablation_full_cm"] = {k: mean(lambda r, k=k: r["ablation"][k]) for k in ABLATION}
    return out


def _mean_of_classes(per_class: dict[str, dict]) -> dict:
    """Each class counts once; nested dicts are averaged key by key, SD of full-body error."""
    values = list(per_class.values())

    def avg(items: list):
        if isinstance(items[0], dict):
            return {k: avg([i[k] for i in items]) for k in items[0]}
        return float(np.mean(items))

    out = avg(values)
    out["trials"] = int(sum(v["trials"] for v in values))
    out["err_cm_full_sd_over_classes"] = float(np.std([v["err_cm"]["full"] for v in values]))
    return out


def run_protocol(
    trials: Sequence[Trial],
    protocol: str,
    method: str = "coolmoves",
    ablation: bool = True,
    setup: VRSetup | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    heading_deg: float = 0.0,
    db_headings: int = 1,
) -> dict:
    """Evaluate ``method`` on ``trials`` under ``protocol``.

    Returns ``{"per_activity": {class: summary}, "overall": summary, "skipped": {...},
    "failed_folds": [...], "folds": n, ...}``; a summary holds ``err_cm``, ``baseline_err_cm``
    (hands, upper, lower, full), ``hand_corr`` and ``baseline_hand_corr`` (left, right),
    ``frames_per_s`` and ``baseline_frames_per_s``, ``ablation_full_cm``, ``trials``.
    ``progress(done, total, label)`` is called after every fold. ``heading_deg`` turns each
    test motion by a random yaw up to this (the database keeps its headings);
    ``db_headings > 1`` adds turned copies to each fold's database (:func:`database_for`).
    """
    if method not in METHODS:
        raise EvaluationError(f"unknown method {method!r}; available: {', '.join(METHODS)}")
    if not trials:
        raise EvaluationError("no trials to evaluate")
    all_folds, skipped = folds(trials, protocol)
    if not all_folds:
        raise EvaluationError(f"no class can be evaluated {protocol}: {skipped}")
    setup = setup or VRSetup()
    rows, failed, cache = [], [], {}
    for i, fold in enumerate(all_folds):
        try:
            rows.extend(
                evaluate_fold(
                    fold, METHODS[method], setup, ablation, cache, heading_deg, db_headings
                )
            )
        except SynthesisError as exc:  # e.g. every training clip fails the correlation filter
            failed.append({"class": fold.cls, "held_out": fold.held_out, "reason": str(exc)})
        if progress is not None:
            progress(i + 1, len(all_folds), f"{fold.cls} / {fold.held_out}")
    per_class = {
        cls: summarise([r for r in rows if r["cls"] == cls])
        for cls in sorted({r["cls"] for r in rows})
    }
    if not per_class:
        raise EvaluationError(f"every fold failed: {failed[:3]}")
    return {
        "method": method,
        "protocol": protocol,
        "per_activity": per_class,
        "overall": _mean_of_classes(per_class),
        "skipped": skipped,
        "failed_folds": failed,
        "folds": len(all_folds),
        "heading_deg": heading_deg,
        "db_headings": db_headings,
        "paper": PAPER,
    }

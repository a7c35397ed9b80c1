"""One leaderboard: every registered synthesis method on the same test motions, scored for
accuracy, for the physics of its output and for speed (``avatarsim eval leaderboard``).

Per fold of the protocol (:func:`synthesis.evaluate.folds`): the database of the fold's
training trials (built once, shared by every CoolMoves variant), the distance threshold
chosen on the training data (:mod:`synthesis.evaluate.validation`), and per test trial one
VR stream that every method (:data:`synthesis.methods.METHODS`) runs on, plus one recording
of each further sensor a selected method declares (``Method.sensors``, recorded by
:data:`RECORDERS`: MoveBox's Kinect V2 skeleton stream, tracked on the rendered depth by the
``Kinect`` device, ControllerPose's controller-camera
keypoints), and AvatarGo's walk-in T-pose sample of the six VR devices, through
:func:`scripts.method_score.score_method` (timed ``step`` calls included). A method's numbers
are means over the trials of a class, then over classes (each class counts once, as the
paper averages over activities); latency percentiles are those of all steps of a trial,
averaged likewise.

A long run resumes: with ``resume`` (the CLI passes ``OUT/folds``) each fold's rows are saved
when it ends (atomically) and a later run with the same settings reuses them
(:func:`saved_fold`).
"""

from __future__ import annotations

import html
import json
from collections.abc import Callable, Sequence
from functools import cache
from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.fileio import write_json
from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams import VRSetup
from avatarsim.render_cams.vr import FULL_BODY
from avatarsim.scripts.dataset import executors
from avatarsim.scripts.method_score import score_method
from avatarsim.scripts.movebox_eval import body17_tracked, filmed
from avatarsim.scripts.report_html import image_html, page, table_html
from avatarsim.sim.thresholds import CheckConfig
from avatarsim.synthesis.avatargo.walk_in import walk_in
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.controllerpose.synthesizer import KeypointRecording
from avatarsim.synthesis.evaluate import (
    EvaluationError,
    Trial,
    database_for,
    folds,
    ik_rig_for,
)
from avatarsim.synthesis.evaluate.validation import choose_max_distance
from avatarsim.synthesis.methods import METHODS, MethodInputs, build, ready_methods

COLUMNS = {
    "hands_cm": "hands",
    "upper_cm": "upper",
    "lower_cm": "lower",
    "full_cm": "full",
    "hand_corr": "hand r",
    "penetration_cm_p95": "pen p95 cm",
    "skate_cm_s_median": "skate cm/s",
    "joint_limit_violation_frac": "limits frac",
    "residual_force_bw_p95": "resid BW p95",
    "step_ms_p50": "step p50 ms",
    "step_ms_p99": "step p99 ms",
}
"""Leaderboard columns: key in each method's summary -> short header."""
PHYSICS = (
    "penetration_cm_p95",
    "skate_cm_s_median",
    "joint_limit_violation_frac",
    "residual_force_bw_p95",
)
"""The physics checks of each output in the table (:data:`sim.plausibility.CONTRACT_KEYS`)."""


def fisheye_keypoints(motion: Motion, seed: int) -> KeypointRecording:
    """The controller cameras' keypoints of a test motion (ControllerPose's input), the
    detector's errors seeded like the trial's VR stream."""
    from avatarsim.scripts.controllerpose.recording import keypoint_recording
    from avatarsim.sim.humanoid import humanoid_for

    return keypoint_recording(humanoid_for(motion), seed)


RECORDERS: dict[str, Callable[[Motion, int], object]] = {
    "kinect": lambda truth, seed: filmed(truth, seed=seed),
    "fisheye": fisheye_keypoints,
}
"""How to record a sensor beyond the VR stream for a test motion, by the
:class:`~synthesis.methods.MethodInputs` field it fills: ``(truth, seed) -> recording``
(seeded like the trial's VR stream). A method that declares a sensor in ``Method.sensors``
needs an entry here to be on the leaderboard."""


TRACKED_SHARE: dict[str, Callable[[object], float]] = {
    "kinect": lambda kinect: float(body17_tracked(kinect).mean()),
}
"""For a recorded sensor that can lose the performer (out of its view or range): the share of
a trial's frames in which it tracks every body17 joint. A method reading it holds the last
pose elsewhere, so its error there grows with how far the performer went (CMU 102_01, a
basketball drive: MoveBox 99 cm over every tick, 8.7 cm over the tracked ones); the board
reports the share per class beside the errors (:func:`tracked_notes`)."""


def sensors_of(methods: Sequence[str]) -> list[str]:
    """The sensors beyond the VR stream that ``methods`` read, in first-declared order.

    Raises:
        EvaluationError: a method reads a sensor no :data:`RECORDERS` entry records.
    """
    needed = list(dict.fromkeys(s for name in methods for s in METHODS[name].sensors))
    missing = [s for s in needed if s not in RECORDERS]
    if missing:
        raise EvaluationError(
            f"no recorder for sensor(s) {', '.join(missing)} "
            "(avatarsim.scripts.leaderboard.RECORDERS); "
            "leave out the methods that read them"
        )
    return needed


def trial_row(result) -> dict[str, float]:
    """The :data:`COLUMNS` of one :class:`~scripts.method_score.MethodResult`."""
    score, row = result.score, result.score.row()
    out = {f"{g}_cm": v for g, v in score.err_cm.items()}
    out["hand_corr"] = float(np.mean(list(score.hand_corr.values())))
    for key in PHYSICS:
        out[key] = float(result.physics[key])
    out["step_ms_p50"], out["step_ms_p99"] = row["step_ms_p50"], row["step_ms_p99"]
    return out


def fold_rows(fold, setup: VRSetup, methods: Sequence[str], checks: CheckConfig, tune: bool):
    """``[(class, method, row)]`` for every test trial of ``fold`` and every method,
    ``[{"method", "class", "reason"}]`` for each method that failed on a trial, and
    ``[(class, sensor, share)]``: each recorded sensor's :data:`TRACKED_SHARE` per trial."""
    coolmoves = METHODS["coolmoves"].options
    overrides = {}
    if tune:
        overrides["max_distance"] = choose_max_distance(fold.train, fold.protocol, coolmoves, setup)
    database = cache(lambda: database_for(fold.train))
    sensors = sensors_of(methods)
    out, failures, shares = [], [], []
    trackers = set(FULL_BODY) <= set(setup.devices)
    for trial in fold.test:
        stream = setup.sample(trial.motion, seed=trial.seed)
        rig, calibration = ik_rig_for(database().skeleton, trial.motion, setup)
        recordings = {s: RECORDERS[s](trial.motion, trial.seed) for s in sensors}
        shares += [
            (trial.cls, s, TRACKED_SHARE[s](r)) for s, r in recordings.items() if s in TRACKED_SHARE
        ]
        inputs = MethodInputs(
            database,
            standing_height(trial.motion),
            rig,
            calibration,
            dict(overrides),
            walk_in=walk_in(setup, trial.motion, trial.seed) if trackers else None,
            **recordings,
        )
        for name in methods:
            try:  # one method's failure on a trial leaves the others' rows
                result = score_method(build(name, inputs), trial.motion, stream, checks, True)
            except SynthesisError as exc:
                failures.append({"method": name, "class": trial.cls, "reason": str(exc)})
                continue
            out.append((trial.cls, name, trial_row(result)))
    return out, failures, shares


def tracked_summary(shares: list[tuple[str, str, float]], methods: Sequence[str]) -> dict:
    """``{sensor: {"methods", "per_class": {class: mean share}, "mean"}}`` of ``shares``
    (``(class, sensor, share)`` per trial); ``mean`` over classes, as the errors are."""
    out = {}
    for sensor in dict.fromkeys(s for _, s, _ in shares):
        classes = sorted({c for c, s, _ in shares if s == sensor})
        per_class = {
            c: float(np.mean([v for cc, s, v in shares if cc == c and s == sensor]))
            for c in classes
        }
        out[sensor] = {
            "methods": [m for m in methods if sensor in METHODS[m].sensors],
            "per_class": per_class,
            "mean": float(np.mean(list(per_class.values()))),
        }
    return out


def tracked_notes(board: dict) -> list[str]:
    """One line per sensor of ``board["sensor_tracked"]``: how much of the trials it tracked,
    and which methods' errors that qualifies."""
    return [
        f"{sensor}: every body17 joint tracked in {t['mean']:.0%} of frames ("
        + ", ".join(f"{c} {v:.0%}" for c, v in t["per_class"].items())
        + f"); {', '.join(t['methods'])} hold the last pose elsewhere, so their errors "
        "include how far the performer went out of view"
        for sensor, t in board.get("sensor_tracked", {}).items()
    ]


FOLD_FORMAT = 3
"""The saved fold's layout and inputs; 2: with the sensors' tracked shares; 3: the Kinect's
skeleton tracked on its depth (before: the truth plus noise). A fold saved under another
format is recomputed."""


def fold_key(fold, methods: Sequence[str], tune: bool) -> dict:
    """What a fold's rows depend on besides the code: the saved format
    (:data:`FOLD_FORMAT`), protocol, class, held-out group, methods, tuning, and the names (and
    seeds) of its training and test trials."""
    return {
        "format": FOLD_FORMAT,
        "protocol": fold.protocol,
        "class": fold.cls,
        "held_out": fold.held_out,
        "methods": list(methods),
        "tune": tune,
        "train": [t.name for t in fold.train],
        "test": [[t.name, t.seed] for t in fold.test],
    }


def fold_file(fold) -> str:
    """The file name of a fold's saved rows: its class and held-out group. A run on other
    trials (e.g. ``--classes``: :func:`~synthesis.evaluate.library_trials` draws the trials'
    seeds over the selected classes) has another :func:`fold_key` and recomputes it."""
    name = f"{fold.cls}--{fold.held_out}"
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) + ".json"


def saved_fold(path: Path, key: dict, compute: Callable[[], dict]) -> tuple[dict, bool]:
    """``(result, reused)``: the result saved at ``path`` when it was saved for ``key``,
    else ``compute()``, saved there (atomically) for a later run. A result is a JSON dict;
    NaN is saved as null and read back as NaN (:func:`avatar_models.fileio.write_json`)."""
    if path.is_file():
        saved = json.loads(path.read_text())
        if saved.get("key") == key:
            return saved["result"], True
    result = compute()
    write_json(path, {"key": key, "result": result})
    return json.loads(path.read_text())["result"], False


def fold_result(
    i: int,
    fold,
    setup: VRSetup,
    methods: Sequence[str],
    checks: CheckConfig,
    tune: bool,
    resume: Path | None,
) -> tuple[int, dict, bool]:
    """``(i, result, reused)`` for fold ``i``: ``{"rows", "failures"}`` of
    :func:`fold_rows`, or ``{"failed": {"class", "held_out", "reason"}}`` when the fold
    cannot be run (e.g. no training clip passes the correlation filter); saved in and
    reused from ``resume`` when given (:func:`saved_fold`). Module-level: pool workers run it.
    """

    def compute() -> dict:
        try:
            fold_out, fold_failures, fold_shares = fold_rows(fold, setup, methods, checks, tune)
        except SynthesisError as exc:
            return {"failed": {"class": fold.cls, "held_out": fold.held_out, "reason": str(exc)}}
        return {"rows": fold_out, "failures": fold_failures, "shares": fold_shares}

    if resume is None:
        return i, compute(), False
    path = Path(resume) / fold_file(fold)
    return i, *saved_fold(path, fold_key(fold, list(methods), tune), compute)


def _nan_for_null(row: dict) -> dict[str, float]:
    return {k: float("nan") if v is None else float(v) for k, v in row.items()}


def _mean_rows(rows: list[dict]) -> dict[str, float]:
    return {k: float(np.mean([r[k] for r in rows])) for k in rows[0]}


def run_leaderboard(
    trials: Sequence[Trial],
    protocol: str,
    methods: Sequence[str] | None = None,
    setup: VRSetup | None = None,
    checks: CheckConfig | None = None,
    tune: bool = True,
    progress: Callable[[int, int, str], None] | None = None,
    resume: Path | None = None,
    workers: int = 1,
) -> dict:
    """Every method of ``methods`` (default: every registered one that is ready,
    :func:`~synthesis.methods.ready_methods`) on the test trials of
    ``protocol``.

    Returns ``{"protocol", "methods": {name: {column: value}}, "per_class": {class: {name:
    {column: value}}}, "trials", "failed_folds", "failed_methods", "skipped", "resumed",
    "sensor_tracked"}`` (:func:`tracked_summary`); a method that fails on a trial
    (``failed_methods``) leaves the other methods' rows of it.
    ``resume``: a folder where each fold's rows are saved and, from an earlier run with the
    same settings (:func:`fold_key`), reused (``resumed`` counts those folds). ``workers``:
    folds run in that many processes (:func:`scripts.dataset.executors.run`); ``progress``
    is called as each ends, in the order they end.
    """
    methods = list(methods or ready_methods())
    sensors_of(methods)  # every sensor can be recorded, checked before any work
    all_folds, skipped = folds(trials, protocol)
    if not all_folds:
        raise EvaluationError(f"no class can be evaluated {protocol}: {skipped}")
    # Every device, Vive trackers included (AvatarGo's); the others read only theirs.
    setup, checks = setup or VRSetup(devices=FULL_BODY), checks or CheckConfig()
    items = [(i, f, setup, methods, checks, tune, resume) for i, f in enumerate(all_folds)]
    results: list[dict] = [{}] * len(all_folds)
    resumed = 0
    finished = executors.run(fold_result, items, workers=workers)
    for done, (i, result, reused) in enumerate(finished, 1):
        results[i], resumed = result, resumed + reused
        if progress is not None:
            progress(done, len(all_folds), f"{all_folds[i].cls} / {all_folds[i].held_out}")
    rows, failed, method_failures, shares, n_trials = [], [], [], [], 0
    for fold, result in zip(all_folds, results, strict=True):
        if "failed" in result:
            failed.append(result["failed"])
        else:
            rows.extend((c, m, _nan_for_null(r)) for c, m, r in result["rows"])
            method_failures.extend(result["failures"])
            shares.extend(result["shares"])
            n_trials += len(fold.test)
    if not rows:
        raise EvaluationError(f"every fold failed: {failed[:3]}")
    classes = sorted({c for c, _, _ in rows})
    per_class = {c: {} for c in classes}
    for c, m in dict.fromkeys((c, m) for c, m, _ in rows):
        per_class[c][m] = _mean_rows([r for cc, mm, r in rows if cc == c and mm == m])
    # A method is averaged over the classes it ran on (its failures are listed beside).
    overall = {
        m: _mean_rows([per_class[c][m] for c in classes if m in per_class[c]])
        for m in methods
        if any(m in per_class[c] for c in classes)
    }
    return {
        "protocol": protocol,
        "methods": overall,
        "per_class": per_class,
        "trials": n_trials,
        "failed_folds": failed,
        "failed_methods": method_failures,
        "skipped": skipped,
        "resumed": resumed,
        "columns": COLUMNS,
        "sensor_tracked": tracked_summary(shares, methods),
    }


def write_plot(board: dict, path: Path) -> Path:
    """A PNG: full-body error against residual force, one point per method (accuracy
    against physical plausibility), with the hand error as the marker size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for name, s in board["methods"].items():
        ax.scatter(s["full_cm"], s["residual_force_bw_p95"], s=30 + 20 * s["hands_cm"])
        ax.annotate(name, (s["full_cm"], s["residual_force_bw_p95"]), fontsize=8)
    ax.set_xlabel("full-body error (cm)")
    ax.set_ylabel("residual force p95 (body weights)")
    ax.set_title(f"leaderboard, {board['protocol']} (marker size: hand error)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _rows(methods: dict[str, dict]) -> list[list[str]]:
    return [[html.escape(name)] + [f"{s[k]:.3g}" for k in COLUMNS] for name, s in methods.items()]


def render_page(board: dict, plot: Path) -> str:
    """The leaderboard as a self-contained HTML page: the table over classes, the plot, and
    one table per class."""
    header = ["method", *COLUMNS.values()]
    per_class = "".join(
        f"<h3>{html.escape(cls)}</h3>" + table_html(_rows(methods), header)
        for cls, methods in board["per_class"].items()
    )
    body = (
        f"<h1>Leaderboard: {html.escape(board['protocol'])}, {board['trials']} test trials</h1>"
        + "<p>Errors in cm (body17 joints), hand r: input-output hand correlation; physics of "
        + "each output on the humanoid; step latency of the streaming <code>step</code>. Means "
        + "over the trials of a class, then over classes.</p>"
        + table_html(_rows(board["methods"]), header)
        + "".join(f"<p>{html.escape(note)}</p>" for note in tracked_notes(board))
        + image_html(plot, "Accuracy against physical plausibility, per method")
        + "<h2>Per class</h2>"
        + per_class
    )
    return page(f"avatarsim leaderboard {board['protocol']}", body)

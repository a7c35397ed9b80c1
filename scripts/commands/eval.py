"""``avatarsim eval``: the evaluations, one subcommand each with only its own options.

``eval protocol METHOD --library DIR|builtin --protocol cross-subject|cross-trial``:
CoolMoves' accuracy protocols (§4.1) with the IK baseline beside: prints the per-class and
overall tables, writes the contract JSON and Fig. 4-like bar plots into ``--out``.
``eval leaderboard`` runs every registered method instead (:mod:`scripts.leaderboard`) and
writes ``leaderboard.json``, ``.png`` and ``.html`` (each fold's rows saved in ``OUT/folds``:
a rerun with the same settings resumes; delete it after changing the code); ``eval
avatargo-study`` runs AvatarGo's simulated user study, exact against fixed offsets
(:mod:`scripts.avatargo_eval`); ``eval movebox-study`` MoveBox's (:mod:`scripts.movebox_eval`);
``eval controllerpose`` ControllerPose's §5.3 accuracy on a dataset. Exit 2 for bad input
(unknown method or protocol, a folder without clips, cross-subject on clips without subject
labels, an option another evaluation has). The old spellings ``eval METHOD``, ``eval
avatargo`` and ``eval movebox`` run these with a deprecation line (:mod:`scripts.cli_legacy`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.progress import Progress
from rich.table import Table

from avatarsim.avatar_models.fileio import write_json
from avatarsim.scripts.cli_common import (
    JsonOpt,
    KinectSkeletonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    err_console,
    user_errors,
)


def _table(results: dict) -> Table:
    from avatarsim.synthesis.coolmoves.correlation import CORRELATION_THRESHOLD

    turned = f", test turned up to {results['heading_deg']:g} deg" if results["heading_deg"] else ""
    if results["db_headings"] > 1:
        turned += f", database at {results['db_headings']} headings"
    if results["correlation_threshold"] != CORRELATION_THRESHOLD:
        turned += f", hand-foot filter at {results['correlation_threshold']:g}"
    table = Table(
        title=f"{results['method']} {results['protocol']}{turned} (cm; IK baseline in brackets)"
    )
    for col in ("class", "trials", "hands", "upper", "lower", "full", "corr L/R", "frames/s"):
        table.add_column(col, justify="left" if col == "class" else "right")
    rows = {**results["per_activity"], "overall": results["overall"]}
    for name, s in rows.items():
        cells = [
            f"{s['err_cm'][g]:.1f} ({s['baseline_err_cm'][g]:.1f})"
            for g in ("hands", "upper", "lower", "full")
        ]
        corr = f"{s['hand_corr']['left']:.3f}/{s['hand_corr']['right']:.3f}"
        fps = f"{s['frames_per_s']:.0f} ({s['baseline_frames_per_s']:.0f})"
        table.add_row(
            escape(name), str(s["trials"]), *cells, corr, fps, end_section=name == "overall"
        )
    return table


def _board_tables(board: dict) -> list[Table]:
    """The leaderboard as three narrow tables (accuracy, physics, latency), so that method
    names stay whole in an 80-column terminal."""
    from avatarsim.scripts.leaderboard import COLUMNS, PHYSICS

    latency = ("step_ms_p50", "step_ms_p99")
    groups = {
        f"accuracy (cm), {board['protocol']}, {board['trials']} test trials": [
            k for k in COLUMNS if k not in PHYSICS and k not in latency
        ],
        "physics of each output on the humanoid": list(PHYSICS),
        "step latency": list(latency),
    }
    tables = []
    for title, keys in groups.items():
        table = Table(title=f"leaderboard: {title}")
        table.add_column("method", no_wrap=True)
        for key in keys:
            table.add_column(COLUMNS[key], justify="right")
        for name, s in board["methods"].items():
            table.add_row(escape(name), *(f"{s[k]:.3g}" for k in keys))
        tables.append(table)
    return tables


def write_leaderboard(board: dict, out: Path, json_out: Path | None) -> None:
    """Print the leaderboard; write its JSON, plot and page into ``out``."""
    from avatarsim.scripts.leaderboard import render_page, tracked_notes, write_plot

    for table in _board_tables(board):
        console.print(table)
    for note in tracked_notes(board):
        console.print(escape(note))
    for fail in board["failed_folds"]:
        console.print(
            "[yellow]fold failed[/] "
            + escape(f"{fail['class']}/{fail['held_out']}: {fail['reason']}")
        )
    for fail in board.get("failed_methods", []):
        console.print(
            "[yellow]method failed[/] "
            + escape(f"{fail['method']} on {fail['class']}: {fail['reason']}")
        )
    if board.get("resumed"):
        console.print(f"{board['resumed']} fold(s) resumed from {out}/folds")
    out.mkdir(parents=True, exist_ok=True)
    plot = write_plot(board, out / "leaderboard.png")
    (out / "leaderboard.html").write_text(render_page(board, plot))
    board["plot"], board["page"] = str(plot), str(out / "leaderboard.html")
    write_json(out / "leaderboard.json", board)
    emit_json(json_out, board)
    console.print(f"wrote {out}/leaderboard.json, leaderboard.png and leaderboard.html")


def _avatargo_tables(results: dict) -> list[Table]:
    """Per task and condition, as two narrow tables (names whole at 80 columns): errors (cm)
    against the simulated user's own joints (feet and hands: mean of left and right), then
    the knee angle of Fig. 2 (deg; all frames and while the user stands) and the palm."""
    pairs = {"feet": ("l_foot", "r_foot"), "hands": ("l_hand", "r_hand")}
    columns = {
        "joints, cm from the user's own": ("head", "feet", "root", "hands"),
        "knee angle (Fig. 2), deg; palm, cm": ("knee", "knee standing", "palm"),
    }
    keys = {"knee": "knee_err_deg", "knee standing": "standing_knee_err_deg", "palm": "palm_cm"}

    def value(scores: dict, column: str) -> float:
        if column in keys:
            return scores.get(keys[column], float("nan"))
        joints = pairs.get(column, (column,))
        return sum(scores[f"effector_err_cm.{j}"] for j in joints) / len(joints)

    users = len(results["users"])
    tables = []
    for name, cols in columns.items():
        table = Table(title=f"avatargo, {users} simulated users: {name}")
        for col in ("task", "offsets", *cols):
            table.add_column(col, justify="left" if col in ("task", "offsets") else "right")
        for task, variants in results["tasks"].items():
            for kind, scores in variants.items():
                cells = [value(scores, c) for c in cols]
                table.add_row(task, kind, *("-" if math.isnan(v) else f"{v:.2f}" for v in cells))
        tables.append(table)
    return tables


def write_avatargo(results: dict, out: Path, json_out: Path | None) -> None:
    """Print AvatarGo's study table; write its JSON and plot into ``out``."""
    from avatarsim.scripts.avatargo_eval import write_plot

    console.print(f"IK: {results['solver_label']}")
    for table in _avatargo_tables(results):
        console.print(table)
    console.print(results["measure"])
    console.print(
        "exact beat fixed on the standing knee error for "
        f"{results['overall']['exact_beats_fixed_knee']} standing users whose avatar legs differ"
    )
    out.mkdir(parents=True, exist_ok=True)
    results["plot"] = str(write_plot(results, out / "avatargo.png"))
    write_json(out / "avatargo.json", results)
    emit_json(json_out, results)
    console.print(f"wrote {out}/avatargo.json and avatargo.png")


def _movebox_tables(results: dict) -> list[Table]:
    """Means per source and sensor, as two narrow tables (names stay whole at 80 columns).
    Retargeting: share of Kinect frames tracking every body17 joint, Kinect joint error,
    retargeting (noise-free, sensed; cm) under the roll its title names, roll errors
    (hinge/rest/sensor; deg). Method: its roll, jerk (raw/smoothed; m/s^3), error over every
    tick and over tracked ticks (cm), loop seam."""
    columns = {
        "retargeting": ("tracked", "kinect cm", "clean", "sensed", "roll h/r/s"),
        "method": ("roll", "jerk", "full cm", "tracked cm", "seam"),
    }
    used = results["roll"]  # the method's: each sensor's roll as the paper does it
    beyond = "" if used["retargeting"] in used["method"].values() else ", beyond the paper"
    titles = {
        "retargeting": f"movebox retargeting ({used['retargeting']} roll{beyond})",
        "method": "movebox method (the paper's roll per sensor)",
    }
    tables = {}
    for name, cols in columns.items():
        tables[name] = Table(title=f"{titles[name]}, means over takes (eval JSON: all)")
        for col in ("source", "sensor", *cols):
            tables[name].add_column(col, justify="left" if col in ("source", "sensor") else "right")
    for source, sensors in results["summary"].items():
        for sensor, s in sensors.items():
            r, roll, jerk = s["retarget_err_cm"], s.get("roll_err_deg"), s["jitter_m_s3"]
            rolls = (
                "-"
                if roll is None
                else "/".join(f"{roll[k]:.0f}" for k in ("hinge", "rest", "sensor"))
            )
            tables["retargeting"].add_row(
                source,
                sensor,
                f"{s['tracked_frames_frac']:.0%}",
                f"{r['kinect_err_cm']:.1f}",
                f"{r['noise_free']:.2f}",
                f"{r['sensed']:.1f}",
                rolls,
            )
            tables["method"].add_row(
                source,
                sensor,
                used["method"][sensor],
                f"{jerk['unsmoothed'] / 1e3:.0f}k/{jerk['smoothed'] / 1e3:.0f}k",
                f"{s['method']['err_cm']['full']:.1f}",
                f"{s['method']['err_cm_tracked']['full']:.1f}",
                f"{s['loop_seam']['naive']:.1f}/{s['loop_seam']['trimmed']:.1f}",
            )
    return list(tables.values())


def run_movebox(
    library, out, wanted, per_source, duration, quick, audio, kinect, seed, json_out,
    skeleton="tracker",
):  # fmt: skip
    """``eval movebox``: inputs checked first (audio, recorded take), then the evaluation
    (:mod:`scripts.movebox_eval`), the story (:mod:`scripts.movebox_story`) and, with
    ``--kinect``, the recorded take retargeted and saved."""
    from avatarsim.avatar_models.formats import save_motion
    from avatarsim.scripts.movebox_eval import (
        ACTIVITIES,
        audio_files,
        builtin_takes,
        real_takes,
        recorded_take,
        run_movebox_eval,
    )
    from avatarsim.scripts.movebox_story import write_story
    from avatarsim.synthesis.base import SynthesisError

    files = audio_files(audio) if audio is not None else []
    take = recorded_take(kinect) if kinect is not None else None
    duration = min(duration, 2.0) if quick else duration
    if library == "builtin":
        chosen = wanted or (["walk"] if quick else list(ACTIVITIES))
        unknown = sorted(set(chosen) - set(ACTIVITIES))
        if unknown:
            raise SynthesisError(f"movebox evaluates {', '.join(ACTIVITIES)}; not {unknown}")
        takes = builtin_takes(chosen, duration, seed)
    else:
        folder = Path(library)
        if not folder.is_dir():
            raise SynthesisError(f"--library must be 'builtin' or a folder; {folder} is not")
        takes = real_takes(folder, per_source or 1, duration)
    with Progress(console=err_console, transient=True) as bar:
        task = bar.add_task("movebox", total=len(takes))
        results = run_movebox_eval(
            takes,
            seed=seed,
            audio=files,
            skeleton=skeleton,
            progress=lambda done, total, label: bar.update(
                task, completed=done, description=escape(label)
            ),
        )
    results.update(library=library, quick=quick)
    for table in _movebox_tables(results):
        console.print(table)
    console.print(f"Kinect skeleton: {results['skeleton']}")
    for name, row in results.get("lip_sync", {}).items():
        console.print(f"lip sync {escape(name)}: jaw vs RMS envelope r = {row['r_jaw_rms']:.3f}")
    results["story"] = write_story(out / "story", 2.0 if quick else 4.0, seed, (files or [None])[0])
    if take is not None:
        recording = take.record()
        results["take"] = {
            "frames": recording.n_frames,
            "files": [str(save_motion(recording, out / f"take{ext}")) for ext in (".npz", ".bvh")],
        }
    write_json(out / "movebox.json", results)
    emit_json(json_out, results)
    console.print(f"wrote {out}/movebox.json and {out}/story/ (story.mp4, story.xml)")


# Options shared by several evaluations, each defined once (defaults stay at the commands).
LibraryOpt = Annotated[
    str, typer.Option(help="'builtin' (generator) or a mocap folder (Bandai, CMU).")
]
ProtocolOpt = Annotated[
    str, typer.Option(help="cross-subject (leave one subject out) or cross-trial.")
]
OutOpt = Annotated[Path, typer.Option(help="Folder for JSON and plots.")]
ClassesOpt = Annotated[
    str | None, typer.Option(help="Comma-separated classes (activities/styles) to keep.")
]
ClassByOpt = Annotated[
    str | None, typer.Option(help="activity or style (default: style for Bandai).")
]
MaxPerClassOpt = Annotated[
    int | None, typer.Option(help="At most this many clips per class (subsampling).")
]
SubjectsOpt = Annotated[int, typer.Option(help="builtin: subjects per activity.")]
TakesOpt = Annotated[int, typer.Option(help="builtin: takes per subject and activity.")]
DurationOpt = Annotated[float, typer.Option(help="builtin: seconds per take.")]
QuickOpt = Annotated[bool, typer.Option(help="Small inputs, for a smoke run.")]

OLD_NAMES = {"avatargo": "avatargo-study", "movebox": "movebox-study"}


def _old_eval(args: list[str], commands) -> tuple[list[str], str] | None:
    """``eval METHOD ...`` -> ``eval protocol METHOD ...``; ``eval avatargo``/``movebox`` ->
    ``eval avatargo-study``/``movebox-study``."""
    from avatarsim.scripts.cli_legacy import is_new_spelling

    if is_new_spelling(args, commands) or args[0].startswith("-"):
        return None
    name = args[0]
    if name in OLD_NAMES:
        return [OLD_NAMES[name], *args[1:]], f"eval {name}: use eval {OLD_NAMES[name]}"
    return ["protocol", *args], f"eval {name}: use eval protocol {name}"


def _check_ranges(*checks: tuple[str, float, float, float]) -> None:
    """Each ``(option, value, lo, hi)`` within ``[lo, hi]`` (NaN is not)."""
    from avatarsim.synthesis.evaluate import EvaluationError

    for option, value, lo, hi in checks:
        if not lo <= value <= hi:  # also NaN
            raise EvaluationError(f"{option} must be from {lo:g} to {hi:g}, got {value}")


def _check_source(library: str, max_per_class: int | None, duration: float) -> None:
    """The options every evaluation on motions has: the source, subsampling, take length."""
    from avatarsim.synthesis.evaluate import EvaluationError

    _check_ranges(
        ("--duration", duration, 0.5, 600.0),
        ("--max-per-class", 1 if max_per_class is None else max_per_class, 1, 100_000),
    )
    if library != "builtin" and not Path(library).is_dir():
        raise EvaluationError(f"--library must be 'builtin' or a folder; {library} is not")


def _check_protocol(protocol: str) -> None:
    from avatarsim.synthesis.evaluate import PROTOCOLS, EvaluationError

    if protocol not in PROTOCOLS:
        raise EvaluationError(f"unknown protocol {protocol!r}; use {' or '.join(PROTOCOLS)}")


def _class_list(classes: str | None) -> list[str] | None:
    return None if classes is None else [c.strip() for c in classes.split(",") if c.strip()]


def _trials(
    library: str,
    wanted: list[str] | None,
    class_by: str | None,
    max_per_class: int | None,
    subjects: int,
    takes: int,
    duration: float,
    quick: bool,
    seed: int,
) -> tuple[list, float]:
    """The trials to evaluate and the seconds per built-in take (``--quick`` shrinks both)."""
    from avatarsim.synthesis.evaluate import builtin_trials, library_trials

    _check_ranges(("--subjects", subjects, 1, 50), ("--takes", takes, 1, 20))
    if quick:
        subjects, takes, duration = min(subjects, 3), min(takes, 2), min(duration, 3.0)
        max_per_class = min(max_per_class or 6, 6)
        wanted = wanted or (["box", "run"] if library == "builtin" else None)
    if library != "builtin":
        return library_trials(Path(library), class_by, wanted, max_per_class, seed), duration
    kwargs = {} if wanted is None else {"activities": wanted}
    trials = builtin_trials(
        n_subjects=subjects, n_takes=takes, duration_s=duration, seed=seed, **kwargs
    )
    return trials, duration


def _progress(bar: Progress, label: str):
    """A progress callback ``(done, total, label)`` on a new task of ``bar``."""
    task = bar.add_task(label, total=None)

    def progress(done: int, total: int, label: str) -> None:
        bar.update(task, completed=done, total=total, description=escape(label))

    return progress


def write_protocol(results: dict, out: Path, json_out: Path | None) -> None:
    """Print a protocol's tables and notes; write its JSON and plots into ``out``."""
    from avatarsim.synthesis.report_plots import write_plots

    console.print(_table(results))
    if "ablation_full_cm" in results["overall"]:
        steps = results["overall"]["ablation_full_cm"]
        console.print(
            "ablation (full body, cm): "
            + " -> ".join(f"{k} {v:.1f}" for k, v in steps.items())
            + "  (paper cross-subject: 16.5 -> 13.2 -> 11.4)"
        )
    for cls, reason in results["skipped"].items():
        console.print(f"[yellow]skipped[/] {escape(cls)}: {escape(str(reason))}")
    for fail in results["failed_folds"]:
        console.print(
            "[yellow]fold failed[/] "
            + escape(f"{fail['class']}/{fail['held_out']}: {fail['reason']}")
        )
    results["plots"] = write_plots(results, out)
    write_json(out / "eval.json", results)
    emit_json(json_out, results)
    console.print(f"wrote {out}/eval.json and {', '.join(results['plots'].values())}")


def register(app: typer.Typer) -> None:
    from avatarsim.scripts.cli_legacy import legacy_group

    group = typer.Typer(
        cls=legacy_group(_old_eval),
        no_args_is_help=True,
        help="Evaluations: a method's accuracy protocols, the leaderboard, the papers' studies.",
    )
    app.add_typer(group, name="eval")

    @group.command()
    @user_errors
    def protocol(
        method: Annotated[
            str,
            typer.Argument(
                help="coolmoves (the paper's), coolmoves+arm-ik, coolmoves-gmm, "
                "coolmoves-centroid-align, coolmoves-own-hand-align (avatarsim.synthesis.methods)."
            ),
        ],
        library: LibraryOpt = "builtin",
        protocol: ProtocolOpt = "cross-subject",
        out: OutOpt = Path("out/eval"),
        classes: ClassesOpt = None,
        class_by: ClassByOpt = None,
        max_per_class: MaxPerClassOpt = None,
        subjects: SubjectsOpt = 5,
        takes: TakesOpt = 2,
        duration: DurationOpt = 8.0,
        ablation: Annotated[bool, typer.Option(help="Also run the ablation variants.")] = True,
        heading: Annotated[
            float, typer.Option(help="Turn each test motion by a random yaw up to this (deg).")
        ] = 0.0,
        db_headings: Annotated[
            int, typer.Option(help="Database copies turned to this many yaws (beyond the paper).")
        ] = 1,
        correlation_threshold: Annotated[
            float | None,
            typer.Option(
                help="Hand-foot filter threshold of the database (default: the paper's 0.1; "
                "another value goes beyond the paper, -1 keeps every trial)."
            ),
        ] = None,
        quick: QuickOpt = False,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Accuracy protocols of a synthesis method, IK baseline beside (CoolMoves §4.1)."""
        from avatarsim.synthesis.coolmoves.correlation import CORRELATION_THRESHOLD
        from avatarsim.synthesis.evaluate import EVALUABLE, EvaluationError, run_protocol

        if correlation_threshold is None:
            correlation_threshold = CORRELATION_THRESHOLD
        if method not in EVALUABLE:
            raise EvaluationError(
                f"unknown method {method!r}; available: {', '.join(EVALUABLE)} "
                "(other evaluations: avatarsim eval --help)"
            )
        _check_protocol(protocol)
        _check_source(library, max_per_class, duration)
        _check_ranges(
            ("--heading", heading, 0.0, 180.0),
            ("--db-headings", db_headings, 1, 36),
            ("--correlation-threshold", correlation_threshold, -1.0, 1.0),
        )
        check_outputs(json_out=json_out, out=out)
        trials, _ = _trials(
            library, _class_list(classes), class_by, max_per_class, subjects, takes, duration,
            quick, seed,
        )  # fmt: skip
        with Progress(console=err_console, transient=True) as bar:
            results = run_protocol(
                trials,
                protocol,
                method,
                ablation,
                progress=_progress(bar, f"{method} {protocol}"),
                heading_deg=heading,
                db_headings=db_headings,
                correlation_threshold=correlation_threshold,
            )
        results.update(
            library=library, seed=seed, quick=quick, class_by=class_by, trials_total=len(trials)
        )
        write_protocol(results, out, json_out)

    @group.command()
    @user_errors
    def leaderboard(
        library: LibraryOpt = "builtin",
        protocol: ProtocolOpt = "cross-subject",
        out: OutOpt = Path("out/eval"),
        classes: ClassesOpt = None,
        class_by: ClassByOpt = None,
        max_per_class: MaxPerClassOpt = None,
        subjects: SubjectsOpt = 5,
        takes: TakesOpt = 2,
        duration: DurationOpt = 8.0,
        methods: Annotated[
            str | None,
            typer.Option(help="Comma-separated methods (default: every ready one)."),
        ] = None,
        workers: Annotated[int, typer.Option(help="Folds run in this many processes.")] = 1,
        quick: QuickOpt = False,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Every registered method on the same test motions: accuracy, physics, latency.

        scripts/leaderboard.py. Each fold's rows are saved in OUT/folds: a rerun with the same
        settings resumes."""
        from avatarsim.scripts.leaderboard import run_leaderboard
        from avatarsim.synthesis.evaluate import EvaluationError
        from avatarsim.synthesis.methods import METHODS

        board_methods = None if methods is None else [m.strip() for m in methods.split(",")]
        if board_methods is not None and (
            not board_methods or any(m not in METHODS for m in board_methods)
        ):
            raise EvaluationError(
                f"--methods takes a comma-separated list of {', '.join(METHODS)}; got {methods!r}"
            )
        _check_protocol(protocol)
        _check_source(library, max_per_class, duration)
        _check_ranges(("--workers", workers, 1, 256))
        check_outputs(json_out=json_out, out=out)
        trials, _ = _trials(
            library, _class_list(classes), class_by, max_per_class, subjects, takes, duration,
            quick, seed,
        )  # fmt: skip
        with Progress(console=err_console, transient=True) as bar:
            progress = _progress(bar, f"leaderboard {protocol}")

            def fold_done(done: int, total: int, label: str) -> None:
                # A line per fold too: a long leaderboard is often run into a log file.
                progress(done, total, label)
                err_console.print(f"fold {done}/{total} done: {escape(label)}")

            board = run_leaderboard(
                trials,
                protocol,
                board_methods,
                progress=fold_done,
                resume=out / "folds",
                workers=workers,
            )
        board.update(library=library, seed=seed, quick=quick, class_by=class_by)
        write_leaderboard(board, out, json_out)

    @group.command(name="avatargo-study")
    @user_errors
    def avatargo_study(
        library: LibraryOpt = "builtin",
        out: OutOpt = Path("out/eval"),
        classes: ClassesOpt = None,
        class_by: ClassByOpt = None,
        max_per_class: MaxPerClassOpt = None,
        subjects: SubjectsOpt = 5,
        takes: TakesOpt = 2,
        duration: DurationOpt = 8.0,
        solver: Annotated[
            str,
            typer.Option(
                help="Per-tick IK, each in place of the paper's Unity IK: analytic (closed-form "
                "two-bone IK), mink or least-squares."
            ),
        ] = "analytic",
        limb_spread: Annotated[
            float,
            typer.Option(help="Avatar leg and arm lengths over the user's: 1 +- this."),
        ] = 0.10,
        strap_yaw_deg: Annotated[
            float,
            typer.Option(help="Largest turn of a strapped tracker about the limb (degrees)."),
        ] = 15.0,
        quick: QuickOpt = False,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """AvatarGo's simulated user study on the paper's tasks (T1 arms, T2 squats, T3 free):
        exact against fixed offsets, scored against the simulated user's own joints.

        A geometric proxy: the paper's result is a questionnaire (Sense of Embodiment). One
        user per test motion (scripts/avatargo_eval.py); writes avatargo.json and
        avatargo.png."""
        from avatarsim.scripts.avatargo_eval import (
            BUILTIN_ACTIVITIES,
            QUICK_ACTIVITIES,
            run_avatargo_eval,
        )
        from avatarsim.synthesis.avatargo.synthesizer import SOLVERS
        from avatarsim.synthesis.evaluate import EvaluationError

        if solver not in SOLVERS:
            raise EvaluationError(f"--solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
        _check_ranges(
            ("--limb-spread", limb_spread, 0.0, 0.5), ("--strap-yaw-deg", strap_yaw_deg, 0.0, 90.0)
        )
        _check_source(library, max_per_class, duration)
        check_outputs(json_out=json_out, out=out)
        wanted = _class_list(classes)
        if wanted is None and library == "builtin":
            wanted = list(QUICK_ACTIVITIES if quick else BUILTIN_ACTIVITIES)
        trials, duration = _trials(
            library, wanted, class_by, max_per_class, subjects, takes, duration, quick, seed
        )
        with Progress(console=err_console, transient=True) as bar:
            results = run_avatargo_eval(
                trials,
                duration,
                progress=_progress(bar, "avatargo"),
                solver=solver,
                limb_spread=limb_spread,
                strap_yaw_rad=math.radians(strap_yaw_deg),
            )
        results.update(library=library, seed=seed, quick=quick, class_by=class_by)
        write_avatargo(results, out, json_out)

    @group.command(name="movebox-study")
    @user_errors
    def movebox_study(
        library: LibraryOpt = "builtin",
        out: OutOpt = Path("out/eval"),
        classes: ClassesOpt = None,
        max_per_class: Annotated[
            int | None, typer.Option(help="A mocap folder: at most this many takes per source.")
        ] = None,
        duration: Annotated[float, typer.Option(help="Seconds per take.")] = 8.0,
        audio: Annotated[
            Path | None,
            typer.Option(help="A WAV file or folder for lip sync (the story's voice)."),
        ] = None,
        kinect: Annotated[
            Path | None,
            typer.Option(help="A recorded Kinect take folder to retarget and save."),
        ] = None,
        kinect_skeleton: KinectSkeletonOpt = "tracker",
        quick: QuickOpt = False,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """MoveBox's retargeting, roll, smoothing, loops, lip sync and story.

        scripts/movebox_eval.py; writes movebox.json and story/."""
        _check_source(library, max_per_class, duration)
        check_outputs(json_out=json_out, out=out)
        run_movebox(
            library, out, _class_list(classes), max_per_class, duration, quick, audio, kinect,
            seed, json_out, kinect_skeleton,
        )  # fmt: skip

    @group.command()
    @user_errors
    def controllerpose(
        model: Annotated[
            Path, typer.Option(exists=True, help="The run folder (or checkpoint) of the model.")
        ],
        data: Annotated[
            Path,
            typer.Option(exists=True, file_okay=False, help="The dataset folder (its test split)."),
        ],
        no_vr_model: Annotated[
            Path | None,
            typer.Option(exists=True, help="A model trained with --no-vr, for the ablation."),
        ] = None,
        frame_stride: Annotated[int, typer.Option(help="Every k-th camera frame.")] = 3,
        mocap: Annotated[
            Path | None,
            typer.Option(exists=True, file_okay=False, help="Also held-out real clips (BVH) here."),
        ] = None,
        out: OutOpt = Path("out/eval"),
        seed: Annotated[
            int, typer.Option("--seed", help="Seed of the devices rendering --mocap clips.")
        ] = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """ControllerPose §5.3 accuracy on a dataset's held-out split and on real mocap.

        scripts/controllerpose/evaluation.py; writes eval.json and per_joint.png."""
        from avatarsim.scripts.controllerpose.data import mocap_files
        from avatarsim.scripts.controllerpose.evaluation import run_evaluation
        from avatarsim.synthesis.evaluate import EvaluationError

        if frame_stride < 1:
            raise EvaluationError(f"--frame-stride must be at least 1, got {frame_stride}")
        if mocap is not None:
            mocap_files(mocap)
        check_outputs(json_out=json_out, out=out)
        report = run_evaluation(model, data, out, no_vr_model, frame_stride, mocap, seed=seed)
        table = Table(title=f"ControllerPose, §5.3 normalised, test: {report['split']}")
        for column in ("test", "method", "mean cm (SD)", "without hip+torso cm (SD)", "frames"):
            table.add_column(column)
        for split, results in (
            ("dataset", report["results"]),
            (report["real_mocap_is"], report["real_mocap"]),
        ):
            for name, res in (results or {}).items():
                table.add_row(
                    split,
                    name,
                    f"{res['mean_cm']:.2f} ({res['sd_cm']:.2f})",
                    f"{res['limbs_mean_cm']:.2f} ({res['limbs_sd_cm']:.2f})",
                    str(res["frames"]),
                )
        console.print(table)
        paper = report["paper"]
        if report["no_vr_increase_pct"] is not None:
            console.print(f"without VR: {report['no_vr_increase_pct']:+.1f}% (paper: +25.5%)")
        console.print(
            f"paper (§5.3): {paper['mean_cm']} cm (SD {paper['sd_cm']}), "
            f"{paper['limbs_mean_cm']} without hip+torso, on another protocol:"
        )
        for what, differs in report["paper_differs"].items():
            console.print(f"  {what.replace('_', ' ')}: {differs}")
        emit_json(json_out, report)

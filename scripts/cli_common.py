"""Shared pieces of the ``avatarsim`` commands: the app, consoles, options, error handling.

Command modules in ``scripts/commands/`` import from here and define ``register(app)``; the
CLI discovers them, so adding a command never edits ``cli.py``.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import threading
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape

from avatarsim.avatar_models.errors import AvatarsimError, MotionValueError
from avatarsim.scripts.scenario import MIN_FRAMES  # noqa: F401  (re-exported for the commands)

if TYPE_CHECKING:  # imported by the commands that use them (keeps `--help` fast)
    import numpy as np

    from avatarsim.sim.humanoid import Humanoid

INTERNAL_ERROR = 3  # exit code of a bug (0 ok, 1 a check failed, 2 bad input)


def make_app() -> typer.Typer:
    return typer.Typer(
        add_completion=False,
        no_args_is_help=True,
        help="avatarsim: a MuJoCo-grounded simulation testbed for full-body VR avatars.",
    )


console = Console()
err_console = Console(stderr=True)

JsonOpt = Annotated[Path | None, typer.Option("--json", help="Also write the result as JSON here.")]
SeedOpt = Annotated[int, typer.Option("--seed", help="Seed for everything stochastic.")]
KinectSkeletonOpt = Annotated[
    str,
    typer.Option(
        "--kinect-skeleton",
        help="The Kinect's skeleton: tracker (tracked on the rendered depth, as the SDK does) "
        "or oracle-noise (the true joints plus noise: not a sensor, faster).",
    ),
]


def _one_line(text: object) -> str:
    """User text for rich: on one line, with ``[...]`` shown as written (not as markup)."""
    return escape(" ".join(str(text).split()))


def _check_common(kwargs: dict[str, Any]) -> None:
    """Options every command shares, checked before the command runs."""
    seed = kwargs.get("seed")
    if isinstance(seed, int) and seed < 0:
        raise AvatarsimError(f"--seed must be 0 or more (numpy's generators), got {seed}")
    motion = kwargs.get("motion", kwargs.get("src"))
    if kwargs.get("unit") is not None and str(motion).startswith(BUILTIN_PREFIX):
        raise AvatarsimError(f"--unit applies to motion files; {motion} is in metres already")
    skeleton = kwargs.get("kinect_skeleton")
    if skeleton is not None:
        from avatarsim.render_cams.kinect.device import SKELETONS

        if skeleton not in SKELETONS:
            raise AvatarsimError(f"--kinect-skeleton must be one of {SKELETONS}, got {skeleton!r}")


def user_errors(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Turn avatarsim's typed errors into a one-line reason on stderr and exit code 2.

    Anything else is a bug, not bad input: it exits 3 (never 1, which means "a check failed"),
    with the traceback when ``AVATARSIM_DEBUG=1``. Warnings (numpy's RuntimeWarnings...) are
    held back: dropped when the command fails with a reason (which says what went wrong),
    otherwise printed after it, one line each.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with warnings.catch_warnings(record=True) as caught, _terminate_as_exit():
            warnings.simplefilter("default")
            try:
                _check_common(kwargs)
                result = fn(*args, **kwargs)
            except AvatarsimError as exc:
                err_console.print(
                    f"[bold red]error:[/] {_one_line(exc)}", highlight=False, soft_wrap=True
                )
                raise typer.Exit(2) from None
            except (typer.Exit, typer.Abort, KeyboardInterrupt):
                _show(caught)
                raise
            except Exception as exc:
                if os.environ.get("AVATARSIM_DEBUG") == "1":
                    raise
                if isinstance(exc, OSError) and exc.filename is not None:
                    # The file system refused (a full disk, permissions changed meanwhile):
                    # the user's environment, not a bug.
                    err_console.print(
                        f"[bold red]error:[/] {_one_line(exc.filename)}: "
                        f"{_one_line(exc.strerror or exc)}",
                        highlight=False,
                        soft_wrap=True,
                    )
                    raise typer.Exit(2) from None
                err_console.print(
                    f"[bold red]internal error:[/] {type(exc).__name__}: {_one_line(exc)} "
                    "(a bug in avatarsim; rerun with AVATARSIM_DEBUG=1 for the traceback)",
                    highlight=False,
                    soft_wrap=True,
                )
                raise typer.Exit(INTERNAL_ERROR) from None
        _show(caught)
        return result

    return wrapper


def _terminated(signum: int, frame: Any) -> None:  # pragma: no cover - a signal
    raise SystemExit(128 + signum)


@contextlib.contextmanager
def _terminate_as_exit() -> Iterator[None]:
    """SIGTERM (``kill``, a CI timeout) raises SystemExit, which unwinds like an exception, so
    half-written outputs are removed on the way out (as for Ctrl-C)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _show(caught: list[warnings.WarningMessage]) -> None:
    seen = set()
    for w in caught:
        line = f"{w.category.__name__}: {w.message}"
        if line not in seen:
            seen.add(line)
            err_console.print(
                f"[yellow]warning:[/] {_one_line(line)}", highlight=False, soft_wrap=True
            )


def check_outputs(
    *,
    json_out: Path | None = None,
    out: Path | None = None,
    out_owner: str | None = None,
    export: Path | None = None,
    files: dict[str, Path | None] | None = None,
    replaced: dict[str, Path | None] | None = None,
) -> None:
    """Every output path of a command, checked before any work starts (nothing is written):
    ``--json`` (a file), ``--out`` (a folder; with ``out_owner`` one that the command
    replaces whole, see :func:`scripts.results.atomic_dir`), ``--export`` (a folder), other
    ``files`` by option name (none of them an existing file avatarsim did not write) and
    files the command ``replaced`` on purpose (checked by the command: ``--update-baseline``).
    Bad paths raise :class:`AvatarsimError` (exit 2)."""
    from avatarsim.scripts.results import check_output_dir, check_output_file

    check_output_file(json_out, "--json")
    for option, path in (files or {}).items():
        check_output_file(path, option)
    for option, path in (replaced or {}).items():
        check_output_file(path, option, replaced=True)
    check_output_dir(out, "--out", out_owner)
    check_output_dir(export, "--export")
    if out is not None and out_owner is not None:
        root = Path(os.path.abspath(out))
        if root in Path(os.path.abspath(Path.cwd())).parents or root == Path.cwd().absolute():
            raise AvatarsimError(
                f"--out {out} is the current folder or above it, and --out is replaced whole; "
                "choose a folder of its own"
            )
        named = [
            ("--json", json_out),
            ("--export", export),
            *(files or {}).items(),
            *(replaced or {}).items(),
        ]
        for option, path in named:
            if path is None:
                continue
            inside = Path(os.path.abspath(path))
            if inside == root or root in inside.parents:
                raise AvatarsimError(
                    f"{option} {path} is inside --out {out}, which is replaced whole; "
                    "write it elsewhere"
                )


def emit_json(path: Path | None, payload: dict[str, Any], option: str = "--json") -> None:
    """Write ``payload`` to the user's JSON file ``path`` (none when None), never over a file
    avatarsim did not write (:mod:`scripts.output_file`)."""
    if path is not None:
        from avatarsim.avatar_models.fileio import json_text
        from avatarsim.scripts.output_file import write_output

        write_output(path, json_text(payload), option)


def export_viewer(humanoid: Humanoid, qpos: np.ndarray, fps: float, export: Path) -> None:
    """Write ``qpos (T, nq)`` of ``humanoid`` at ``fps`` into ``export`` for MuJoCo's viewer
    (:func:`sim.export.export_replay`) and say how to open it."""
    from avatarsim.sim.export import export_replay

    export_replay(humanoid, qpos, fps, export)
    console.print(
        escape(
            f"MuJoCo viewer files in {export}/ (python -m mujoco.viewer --mjcf {export}/replay.xml)"
        )
    )


def unit_option(unit: str | None) -> dict[str, Any]:
    """``--unit`` as reader options: a unit name or a number of metres per file unit."""
    if unit is None:
        return {}
    try:
        return {"unit": float(unit)}
    except ValueError:
        return {"unit": unit}


BUILTIN_PREFIX = "builtin:"


def load_motion_arg(
    arg: str,
    unit: str | None = None,
    seed: int = 0,
    duration_s: float = 4.0,
    min_frames: int = 1,
    check_height: bool = True,
):
    """A motion file path, ``mocap:RELATIVE/PATH`` inside the mocap folder
    (:mod:`avatarsim.avatar_models.mocap_dir`), or ``builtin:ACTIVITY`` for the built-in
    generator (any command that takes a MOTION accepts all three). A clip shorter than
    ``min_frames`` frames or (with ``check_height``) a body of no person's height is bad
    input."""
    if arg.startswith(BUILTIN_PREFIX):
        from avatarsim.avatar_models.generator import ACTIVITIES, generate

        activity = arg[len(BUILTIN_PREFIX) :]
        if activity not in ACTIVITIES:
            raise AvatarsimError(
                f"unknown built-in activity {activity!r}; built-in: {', '.join(ACTIVITIES)}"
            )
        if unit is not None:
            raise AvatarsimError(f"--unit applies to motion files; {arg} is in metres already")
        return generate(activity, duration_s=duration_s, seed=seed)
    from avatarsim.avatar_models.formats import load_motion
    from avatarsim.avatar_models.measure import check_plausible_height
    from avatarsim.avatar_models.mocap_dir import is_mocap_source, resolve_mocap_source

    path = resolve_mocap_source(arg) if is_mocap_source(arg) else Path(arg)
    m = load_motion(path, **unit_option(unit))
    if m.n_frames < min_frames:
        raise MotionValueError(
            f"{arg}: too short: {m.n_frames} frame(s); this command needs at least "
            f"{min_frames} (velocities and accelerations)"
        )
    if check_height:
        try:
            check_plausible_height(m)
        except MotionValueError as exc:
            raise MotionValueError(f"{arg}: {exc}") from None
    return m

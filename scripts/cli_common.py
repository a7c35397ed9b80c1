"""Shared pieces of the ``avatarsim`` commands: the app, consoles, options, error handling.

Command modules in ``scripts/commands/`` import from here and define ``register(app)``; the
CLI discovers them, so adding a command never edits ``cli.py``.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console

from avatar_models.errors import AvatarsimError

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


def user_errors(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Turn avatarsim's typed errors into a one-line reason on stderr and exit code 2.

    Anything else is a bug, not bad input: it exits 3 (never 1, which means "a check failed"),
    with the traceback when ``AVATARSIM_DEBUG=1``.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except AvatarsimError as exc:
            err_console.print(f"[bold red]error:[/] {exc}", highlight=False, soft_wrap=True)
            raise typer.Exit(2) from None
        except (typer.Exit, typer.Abort, KeyboardInterrupt):
            raise
        except Exception as exc:
            if os.environ.get("AVATARSIM_DEBUG") == "1":
                raise
            err_console.print(
                f"[bold red]internal error:[/] {type(exc).__name__}: {exc} "
                "(a bug in avatarsim; rerun with AVATARSIM_DEBUG=1 for the traceback)",
                highlight=False,
                soft_wrap=True,
            )
            raise typer.Exit(INTERNAL_ERROR) from None

    return wrapper


def emit_json(path: Path | None, payload: dict[str, Any]) -> None:
    if path is not None:
        from scripts.results import write_json

        write_json(path, payload)


def unit_option(unit: str | None) -> dict[str, Any]:
    """``--unit`` as reader options: a unit name or a number of metres per file unit."""
    if unit is None:
        return {}
    try:
        return {"unit": float(unit)}
    except ValueError:
        return {"unit": unit}


BUILTIN_PREFIX = "builtin:"


def load_motion_arg(arg: str, unit: str | None = None, seed: int = 0, duration_s: float = 4.0):
    """A motion file path, or ``builtin:ACTIVITY`` for the built-in generator (any command
    that takes a MOTION accepts both)."""
    if arg.startswith(BUILTIN_PREFIX):
        from avatar_models.generator import ACTIVITIES, generate

        activity = arg[len(BUILTIN_PREFIX) :]
        if activity not in ACTIVITIES:
            raise AvatarsimError(
                f"unknown built-in activity {activity!r}; built-in: {', '.join(ACTIVITIES)}"
            )
        return generate(activity, duration_s=duration_s, seed=seed)
    from avatar_models.formats import load_motion

    return load_motion(Path(arg), **unit_option(unit))

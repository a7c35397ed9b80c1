"""Old spellings of a command group, accepted for one release with a deprecation line.

A group made by :func:`legacy_group` hands its arguments to a ``rewrite`` function before
click parses them: ``rewrite(args, commands)`` returns ``None`` for today's spelling, or the
arguments in today's spelling and the line to print on stderr. Options are never listed
twice: the old spelling runs today's command, with today's options and checks.
"""

from __future__ import annotations

from collections.abc import Callable, Collection

import click
from rich.markup import escape
from typer.core import TyperGroup

from avatarsim.scripts.cli_common import err_console

Rewrite = Callable[[list[str], Collection[str]], "tuple[list[str], str] | None"]


def legacy_group(rewrite: Rewrite) -> type[TyperGroup]:
    """A typer group class (``typer.Typer(cls=...)``) that accepts what ``rewrite`` maps."""

    class LegacyGroup(TyperGroup):
        def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
            rewritten = rewrite(list(args), self.commands)
            if rewritten is not None:
                args, old = rewritten
                err_console.print(
                    f"[yellow]deprecated:[/] {escape(old)}; the old spelling goes in the next "
                    "release",
                    highlight=False,
                    soft_wrap=True,
                )
            return super().parse_args(ctx, args)

    return LegacyGroup


def is_new_spelling(args: list[str], commands: Collection[str]) -> bool:
    """True for no arguments, a request for help, or a subcommand first."""
    return not args or args[0] in commands or args[0] in ("--help", "-h")

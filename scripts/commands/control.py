"""``avatarsim control MOTION``: the MuJoCo humanoid follows a motion under physics, root
unactuated.

By default the search of ``sim.control.search`` (SAMCON-style beam search over the
whole-body controller's targets); ``--plain`` runs the controller alone
(``sim.control.controller``, about 10x real time, lasts a few steps on a walk). A clip shorter
than ``--seconds`` is looped on its best gait cycle (``sim.control.reference.looped``); a
foreign rig is retargeted with its stance feet levelled. Writes ``control.csv``,
``control.json``, ``control.png`` into
``--out`` (replaced only when the run completes), optionally the simulated motion for MuJoCo's
viewer into ``--export``. Exit 1 when the humanoid falls or the search gives up before the
requested time (the reason is in the table and the JSON's ``failure``), 2 for bad input.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from avatarsim.scripts.cli_common import (
    MIN_FRAMES,
    JsonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    err_console,
    export_viewer,
    load_motion_arg,
    user_errors,
)
from avatarsim.scripts.scenario import MAX_CONTROL_S

MAX_SEARCH = 64  # samples or beam: 64 x 64 simulations per window is hours per second


def register(app: typer.Typer) -> None:
    @app.command()
    @user_errors
    def control(
        motion: Annotated[
            str,
            typer.Argument(help="A .bvh, .amc (ASF beside it) or .npz file, or builtin:ACTIVITY."),
        ],
        seconds: Annotated[
            float | None,
            typer.Option(
                help=f"Length to follow (s, at most {MAX_CONTROL_S:g}); loops a shorter clip. "
                "Default: the clip."
            ),
        ] = None,
        plain: Annotated[
            bool, typer.Option("--plain", help="The controller alone, no sampling search.")
        ] = False,
        samples: Annotated[
            int, typer.Option(help=f"Search: samples per kept state (1-{MAX_SEARCH}).")
        ] = 8,
        beam: Annotated[
            int, typer.Option(help=f"Search: states kept per window (1-{MAX_SEARCH}).")
        ] = 6,
        out: Annotated[Path, typer.Option(help="Folder for CSV, JSON and plot.")] = Path(
            "out/control"
        ),
        export: Annotated[
            Path | None, typer.Option(help="Also write the simulated motion for MuJoCo's viewer.")
        ] = None,
        unit: Annotated[str | None, typer.Option(help="File unit (see `info`).")] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Drive the humanoid under physics to follow a motion. Exit 1 if it falls or does not
        reach the requested time."""
        from avatarsim.avatar_models.errors import MotionValueError

        if seconds is not None and not 0 < seconds <= MAX_CONTROL_S:
            raise MotionValueError(
                f"--seconds must be above 0 and at most {MAX_CONTROL_S:g}, got {seconds}"
            )
        if not (1 <= samples <= MAX_SEARCH and 1 <= beam <= MAX_SEARCH):
            raise MotionValueError(f"--samples and --beam must be 1-{MAX_SEARCH}")
        check_outputs(json_out=json_out, out=out, out_owner="control", export=export)
        from avatarsim.scripts.control_run import timed_control
        from avatarsim.scripts.results import atomic_dir
        from avatarsim.sim.control.reference import looped
        from avatarsim.sim.control.report import write_outputs
        from avatarsim.sim.control.search import SearchSettings
        from avatarsim.sim.humanoid import humanoid_for

        m = load_motion_arg(motion, unit, seed, duration_s=seconds or 10.0, min_frames=MIN_FRAMES)
        if seconds is None and m.duration_s > MAX_CONTROL_S:
            raise MotionValueError(
                f"the clip is {m.duration_s:.0f} s long; at most {MAX_CONTROL_S:g} s are followed "
                "(pass --seconds)"
            )
        humanoid = humanoid_for(m, level_feet=True)
        qpos = humanoid.qpos
        if seconds is not None:
            qpos = looped(qpos, m.fps, seconds)
        summary_extra = {"motion": motion, "seed": seed, "fps": m.fps}
        summary_extra |= humanoid.summary()
        search = None if plain else SearchSettings(samples=samples, beam=beam, seed=seed)
        result, summary = timed_control(
            humanoid.control_model(), qpos, m.fps, search, progress_bar=True
        )
        summary |= summary_extra
        wall = summary["wall_s"]
        table = Table(title=f"physics control ({summary['mode']}): {escape(motion)}")
        for col in ("quantity", "value"):
            table.add_column(col)
        fell = "never" if not result.fell else f"[red]at {result.fall_time_s:.2f} s[/]"
        followed = f"{summary['duration_s']:.2f} s of {summary['requested_s']:.2f} s"
        outcome = "[green]completed[/]" if summary["completed"] else f"[red]{summary['failure']}[/]"
        rows = [
            ("followed", followed),
            ("outcome", outcome),
            ("fell", fell),
            (
                "body17 error mean / p95",
                f"{summary['body17_err_cm_mean']:.1f} / {summary['body17_err_cm_p95']:.1f} cm",
            ),
            ("energy", f"{summary['energy_j']:.0f} J"),
            ("mean |torque|", f"{summary['mean_abs_torque_nm']:.1f} N m"),
            ("speed", f"{summary['x_real_time']:.2f}x real time ({wall:.1f} s wall)"),
        ]
        for row in rows:
            table.add_row(*row)
        console.print(table)
        with atomic_dir(out, "control") as partial:
            written = write_outputs(result, summary, partial, f"physics control: {motion}")
        console.print(escape(f"wrote {', '.join(str(out / p.name) for p in written.values())}"))
        if export is not None:
            export_viewer(humanoid, result.qpos, m.fps, export)
        emit_json(json_out, summary)
        if not summary["completed"]:
            upright_s = summary["duration_s"] if not result.fell else result.fall_time_s
            err_console.print(
                f"[red]not followed to the end:[/] {summary['failure']} after "
                f"{upright_s:.2f} s of {summary['requested_s']:.2f} s",
                highlight=False,
            )
            raise typer.Exit(1)

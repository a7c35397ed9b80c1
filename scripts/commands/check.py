"""``avatarsim check MOTION``: physics plausibility of a motion on the humanoid.

Prints the summary table, writes per-frame CSV, the contract JSON and a plot into ``--out``,
optionally the MJCF and keyframes for MuJoCo's viewer into ``--export``. ``--corrupt DEFECT``
first makes the motion wrong in one known way (:mod:`sim.corrupt`), so that the check for it
fails: a quick way to see what each check catches. Exit 1 when a threshold fails, 2 for bad
input (NaN, no frames, unknown rig). A foreign rig is retargeted onto the humanoid
(:func:`sim.humanoid.humanoid_for`) and its residual reported.
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
    export_viewer,
    load_motion_arg,
    user_errors,
)


def corrupted(humanoid, clean_report, defect: str, seed: int):
    """The humanoid of its motion made wrong by ``defect`` (stances from the clean report)."""
    import numpy as np

    from avatarsim.sim.corrupt import corrupt
    from avatarsim.sim.humanoid import humanoid_for

    stance = clean_report.per_frame()["contact_left"] > 0
    rng = np.random.default_rng(seed)
    return humanoid_for(corrupt(defect, humanoid.motion, humanoid.body, stance, rng))


def register(app: typer.Typer) -> None:
    @app.command()
    @user_errors
    def check(
        motion: Annotated[
            str,
            typer.Argument(help="A .bvh, .amc (ASF beside it) or .npz file, or builtin:ACTIVITY."),
        ],
        out: Annotated[Path, typer.Option(help="Folder for CSV, JSON and plot.")] = Path(
            "out/check"
        ),
        export: Annotated[
            Path | None, typer.Option(help="Also write MJCF + keyframes for MuJoCo's viewer.")
        ] = None,
        config: Annotated[
            Path | None, typer.Option(help="TOML with definitions/thresholds to override.")
        ] = None,
        corrupt: Annotated[
            str | None,
            typer.Option(
                help="Make the motion wrong first, in the way one check flags: penetration, "
                "floating, joint_limits, skating or jitter (that check must then fail)."
            ),
        ] = None,
        unit: Annotated[str | None, typer.Option(help="File unit (see `info`).")] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Physics plausibility of a motion on the MuJoCo humanoid. Exit 1 if a check fails."""
        from avatarsim.avatar_models.errors import AvatarsimError
        from avatarsim.sim.corrupt import DEFECTS

        if corrupt is not None and corrupt not in DEFECTS:
            raise AvatarsimError(f"--corrupt {corrupt!r}: defects are {', '.join(DEFECTS)}")
        check_outputs(json_out=json_out, out=out, export=export)
        from avatarsim.sim.humanoid import humanoid_for
        from avatarsim.sim.plausibility import check_humanoid
        from avatarsim.sim.report import summary_rows, write_outputs
        from avatarsim.sim.thresholds import CheckConfig

        cfg = CheckConfig.from_toml(config) if config is not None else CheckConfig()
        m = load_motion_arg(motion, unit, seed, min_frames=MIN_FRAMES)
        humanoid = humanoid_for(m)
        report = check_humanoid(humanoid, cfg)
        if corrupt is not None:
            humanoid = corrupted(humanoid, report, corrupt, seed)
            report = check_humanoid(humanoid, cfg)
            report.meta["corrupt"] = corrupt
        report.meta.update(path=str(motion), seed=seed)
        table = Table(title=f"physics plausibility: {escape(motion)}")
        for col in ("check", "value", "threshold", "passed"):
            table.add_column(col)
        for name, value, limit, ok in summary_rows(report):
            table.add_row(
                name, f"{value:.4g}", f"{limit:g}", "[green]yes[/]" if ok else "[red]NO[/]"
            )
        console.print(table)
        written = write_outputs(report, out)
        if export is not None:
            export_viewer(humanoid, humanoid.qpos, m.fps, export)
        console.print(escape(f"wrote {', '.join(str(p) for p in written.values())}"))
        emit_json(json_out, report.contract())
        if not report.passed:
            raise typer.Exit(1)

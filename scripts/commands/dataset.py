"""``avatarsim dataset generate|info|verify|preview``: sharded synthetic datasets.

``generate CONFIG --out DIR`` writes WebDataset-style shards and a manifest, resuming a run
of the same config and seed in ``DIR``; ``info DIR`` summarises a dataset; ``verify DIR``
checks hashes, counts, completeness and splits (exit 1 when a check fails); ``preview DIR``
draws random samples with their ground-truth skeleton. Bad input (an
unknown config key, an empty source, split fractions not summing to 1, an unwritable or
foreign ``--out``) exits 2 before anything is written.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from avatarsim.scripts.cli_common import (
    JsonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    err_console,
    make_app,
    user_errors,
)

DirArg = Annotated[Path, typer.Argument(help="A dataset folder (written by generate).")]


def register(app: typer.Typer) -> None:
    dataset = make_app()
    dataset.info.help = "Sharded synthetic datasets: generate, info, verify, preview."
    app.add_typer(dataset, name="dataset")

    @dataset.command()
    @user_errors
    def generate(
        config: Annotated[Path, typer.Argument(help="Dataset config TOML.")],
        out: Annotated[Path, typer.Option(help="Dataset folder (resumed when it holds a run).")],
        workers: Annotated[
            int, typer.Option(help="Shards made at once: processes (local) or Ray tasks.")
        ] = 1,
        executor: Annotated[str, typer.Option(help="local (process pool) or ray.")] = "local",
        address: Annotated[
            str | None,
            typer.Option(
                help="Ray cluster to attach to (auto, HOST:PORT, ray://HOST:10001); "
                "default: a new local Ray instance of --workers CPUs."
            ),
        ] = None,
        seed: Annotated[
            int | None, typer.Option("--seed", help="Override the config's seed.")
        ] = None,
        json_out: JsonOpt = None,
    ) -> None:
        """Generate (or resume) a sharded dataset: shards, then the manifest."""
        from avatarsim.scripts.dataset.config import load_config
        from avatarsim.scripts.dataset.executors import check_executor
        from avatarsim.scripts.dataset.plan import plan_samples
        from avatarsim.scripts.dataset.runner import generate as run_generate

        check_executor(executor, workers, address)
        check_outputs(json_out=json_out, out=out)
        cfg = load_config(config).with_seed(seed)
        plan_samples(cfg)  # a config whose plan fails (an empty mocap source) writes nothing
        with Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=err_console,
        ) as progress:
            task = progress.add_task("samples", total=None)

            def started(total: int, done: int) -> None:
                progress.update(task, total=total, completed=done)
                progress.reset(task, total=total, completed=done)

            result = run_generate(
                cfg,
                out,
                workers,
                on_start=started,
                on_shard=lambda n: progress.advance(task, n),
                executor=executor,
                address=address,
            )
        rate = result.made_samples / max(result.seconds, 1e-9)
        payload = {
            "out": str(out),
            "config_hash": result.manifest["config_hash"],
            "shards": result.shards,
            "samples": result.samples,
            "frames": result.frames,
            "shards_made": result.made,
            "shards_resumed": result.shards - result.made,
            "seconds": round(result.seconds, 3),
            "samples_per_s": round(rate, 3),
            "workers": workers,
            "executor": executor,
        }
        console.print(
            escape(
                f"{out}: {result.shards} shards, {result.samples} samples, {result.frames} "
                f"frames ({result.made} shards made, {result.shards - result.made} resumed) "
                f"in {result.seconds:.1f} s, {rate:.2f} samples/s"
            )
        )
        emit_json(json_out, payload)

    @dataset.command()
    @user_errors
    def info(path: DirArg, seed: SeedOpt = 0, json_out: JsonOpt = None) -> None:
        """Counts per split, frames, shards and the config of a dataset."""
        from avatarsim.scripts.dataset.manifest import read_manifest

        check_outputs(json_out=json_out)
        manifest = read_manifest(path)
        table = Table(title=escape(f"dataset {manifest['name']}"))
        for col in ("split", "shards", "samples", "frames", "groups"):
            table.add_column(col)
        for split, c in manifest["counts"].items():
            table.add_row(
                split, *(str(c[k]) for k in ("shards", "samples", "frames")), str(len(c["groups"]))
            )
        console.print(table)
        console.print(escape(f"config hash {manifest['config_hash']}"))
        # Nothing here is random; the seed is accepted and recorded as every command's is.
        payload = {k: v for k, v in manifest.items() if k != "shards"}
        emit_json(json_out, payload | {"shards": len(manifest["shards"]), "seed": seed})

    @dataset.command()
    @user_errors
    def preview(
        path: DirArg,
        out: Annotated[Path, typer.Option(help="The picture sheet to write (PNG).")] = Path(
            "out/dataset-preview.png"
        ),
        samples: Annotated[int, typer.Option(help="Random samples on the sheet.")] = 12,
        split: Annotated[
            str | None, typer.Option(help="Only this split (train, val, test).")
        ] = None,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """A picture sheet of random samples with the ground-truth skeleton drawn on (the
        fisheye camera that sees most of it, else a side view)."""
        from avatarsim.avatar_models.errors import AvatarsimError
        from avatarsim.scripts.dataset.config import SPLITS
        from avatarsim.scripts.dataset.preview import preview_sheet

        if samples < 1:
            raise AvatarsimError(f"--samples must be at least 1, got {samples}")
        if split is not None and split not in SPLITS:
            raise AvatarsimError(f"--split must be one of {', '.join(SPLITS)}, got {split!r}")
        check_outputs(json_out=json_out, files={"--out": out})
        panels = preview_sheet(path, out, samples, seed, split)
        console.print(escape(f"{out}: {len(panels)} samples"))
        emit_json(json_out, {"out": str(out), "panels": panels, "seed": seed})

    @dataset.command()
    @user_errors
    def verify(path: DirArg, seed: SeedOpt = 0, json_out: JsonOpt = None) -> None:
        """Check shard hashes, counts, that nothing is lost or duplicated, and that no
        held-out subject or clip reaches train. Exit 1 when a check fails."""
        from avatarsim.scripts.dataset.verify import verify_dataset

        check_outputs(json_out=json_out)
        report = verify_dataset(path)
        for problem in report.problems:
            err_console.print(f"[red]problem:[/] {escape(problem)}", highlight=False)
        verdict = "[green]ok[/]" if report.passed else "[red]FAILED[/]"
        console.print(
            f"{verdict}: {report.shards} shards, {report.samples} samples, "
            f"{report.frames} frames verified"
        )
        emit_json(
            json_out,
            {
                "passed": report.passed,
                "problems": report.problems,
                "shards": report.shards,
                "samples": report.samples,
                "frames": report.frames,
                "seed": seed,  # nothing is random; recorded as every command's is
            },
        )
        if not report.passed:
            raise typer.Exit(1)

"""The ``avatarsim`` command line (typer). Exit codes: 0 ok, 1 a check failed, 2 bad input.

Core commands live here; capability commands (``check``, ``eval``, ``render``...) live in
``scripts/commands/*.py`` as ``register(app)`` and are discovered at import.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.mocap_dir import MOCAP_ENV, mocap_dir
from avatarsim.scripts import commands
from avatarsim.scripts.cli_common import (
    JsonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    err_console,
    load_motion_arg,
    make_app,
    user_errors,
)

app = make_app()


@app.command()
@user_errors
def info(
    motion: Annotated[
        str, typer.Argument(help="A .bvh, .amc (ASF beside it) or .npz file, or builtin:ACTIVITY.")
    ],
    unit: Annotated[
        str | None, typer.Option(help="File unit: cm, inch, m, cmu or metres per unit.")
    ] = None,
    seed: SeedOpt = 0,
    json_out: JsonOpt = None,
) -> None:
    """Skeleton, fps, frames and size of a motion file."""
    from avatarsim.avatar_models.errors import MotionValueError
    from avatarsim.avatar_models.measure import check_plausible_height, standing_height

    check_outputs(json_out=json_out)
    m = load_motion_arg(motion, unit, seed, check_height=False)
    notes = []
    try:
        check_plausible_height(m)
    except MotionValueError as exc:
        notes.append(f"[yellow]warning:[/] {escape(str(exc))}; other commands refuse it")
    dropped = m.meta.get("dropped_frames")
    if dropped:
        notes.append(f"dropped frame(s) {dropped['frames']} of the file: {dropped['reason']}")
    payload = {
        "path": str(motion),
        "joints": m.skeleton.n_joints,
        "joint_names": list(m.skeleton.names),
        "fps": m.fps,
        "frames": m.n_frames,
        "duration_s": m.duration_s,
        "height_m": standing_height(m),
        "dropped_frames": dropped or None,
    }
    table = Table(title=escape(Path(motion).name), show_header=False)
    for key in ("joints", "fps", "frames", "duration_s", "height_m"):
        value = payload[key]
        table.add_row(key, f"{value:.3f}" if isinstance(value, float) else str(value))
    console.print(table)
    for note in notes:
        console.print(note, highlight=False, soft_wrap=True)
    emit_json(json_out, payload)


@app.command()
@user_errors
def convert(
    src: Annotated[str, typer.Argument(help="Input .bvh, .amc or .npz, or builtin:ACTIVITY.")],
    dst: Annotated[Path, typer.Argument(help="Output .bvh or .npz.")],
    fps: Annotated[float | None, typer.Option(help="Resample to this frame rate.")] = None,
    unit: Annotated[str | None, typer.Option(help="Input unit (see `info`).")] = None,
    seed: SeedOpt = 0,
    json_out: JsonOpt = None,
) -> None:
    """Convert BVH / ASF+AMC / NPZ to BVH or NPZ, optionally resampled."""
    from avatarsim.avatar_models.formats import WRITABLE, save_motion
    from avatarsim.avatar_models.motion import check_fps
    from avatarsim.scripts.output_file import record_output

    if fps is not None:
        check_fps(fps, "--fps")
    check_outputs(json_out=json_out, files={"OUT": dst})
    if dst.suffix.lower() not in WRITABLE:
        raise AvatarsimError(
            f"OUT {dst}: cannot write {dst.suffix or 'a file without suffix'}; "
            f"writable: {', '.join(WRITABLE)}"
        )
    m = load_motion_arg(src, unit, seed)
    if fps is not None:
        m = m.resample(fps)
    record_output(save_motion(m, dst))
    console.print(f"wrote {escape(str(dst))}: {m.n_frames} frames at {m.fps:g} fps")
    emit_json(json_out, {"src": str(src), "dst": str(dst), "frames": m.n_frames, "fps": m.fps})


def _run(scenario_obj: Any, out: Path, json_out: Path | None) -> None:
    from avatarsim.scripts.pipeline import run_scenario

    results = run_scenario(scenario_obj, out, err_console)
    table = Table(title=f"scenario {escape(results['scenario'])}")
    for col in ("check", "value", "threshold", "passed"):
        table.add_column(col)
    for c in results["checks"]:
        mark = "[green]yes[/]" if c["passed"] else "[red]NO[/]"
        table.add_row(c["name"], f"{c['value']:.4g}", escape(str(c["threshold"])), mark)
    console.print(table)
    outputs = ", ".join(sorted(results["outputs"].values()))
    console.print(f"results in {escape(str(out))}/ ({escape(outputs)})")
    emit_json(json_out, results)
    if not results["passed"]:
        raise typer.Exit(1)


@app.command()
@user_errors
def run(
    scenarios: Annotated[
        list[Path],
        typer.Argument(
            help="Scenario TOML files and folders (searched for *.toml).", show_default=False
        ),
    ],
    out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out/run"),
    seed: Annotated[
        int | None, typer.Option("--seed", help="Override every scenario's seed.")
    ] = None,
    workers: Annotated[int, typer.Option(help="Scenarios run in parallel processes.")] = 1,
    fail_fast: Annotated[bool, typer.Option(help="Stop at the first failure.")] = False,
    select: Annotated[
        str | None, typer.Option("-k", help="Only scenarios whose name contains or matches this.")
    ] = None,
    baseline: Annotated[
        Path | None,
        typer.Option(help="Compare metrics with this suite folder or results.json."),
    ] = None,
    update_baseline: Annotated[
        bool, typer.Option(help="Write this run's results as the new --baseline.")
    ] = False,
    json_out: JsonOpt = None,
) -> None:
    """Run scenarios: source -> devices -> methods -> checks. Exit 1 if a threshold fails.

    One scenario file writes its outputs into --out. Several, a folder, -k or a baseline make
    a suite: a folder per scenario plus junit.xml, results.json and index.html for them all.
    """
    from avatarsim.scripts.suite.command import (
        SuiteOptions,
        check_options,
        print_summary,
        run_paths,
    )
    from avatarsim.scripts.suite.regression import baseline_file

    options = SuiteOptions(workers, fail_fast, select, baseline, update_baseline, seed)
    check_options(options)
    replaced = {"--baseline": baseline_file(baseline) if update_baseline else None}
    check_outputs(json_out=json_out, out=out, out_owner="run", replaced=replaced)
    if len(scenarios) == 1 and scenarios[0].is_file() and not (select or baseline):
        from avatarsim.scripts.scenario import load_scenario

        sc = load_scenario(scenarios[0])
        if seed is not None:
            sc = dataclasses.replace(sc, seed=seed)
        _run(sc, out, json_out)
        return
    results = run_paths(scenarios, out, options, err_console)
    print_summary(results, out, console)
    emit_json(json_out, results)
    if not results["passed"]:
        raise typer.Exit(1)


@app.command()
@user_errors
def demo(
    out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out/demo"),
    seed: SeedOpt = 0,
    json_out: JsonOpt = None,
) -> None:
    """The default scenario on built-in motion, end to end (results, pictures)."""
    from avatarsim.scripts.scenario import DEFAULT_SCENARIO, load_scenario

    check_outputs(json_out=json_out, out=out, out_owner="run")
    sc = dataclasses.replace(load_scenario(DEFAULT_SCENARIO), seed=seed)
    _run(sc, out, json_out)


@app.command()
@user_errors
def bench(
    name: Annotated[str | None, typer.Argument(help="One benchmark; all when omitted.")] = None,
    quick: Annotated[bool, typer.Option(help="Smaller inputs, for a smoke run.")] = False,
    seed: SeedOpt = 0,
    json_out: JsonOpt = None,
    mocap: Annotated[
        Path | None,
        typer.Option(
            help="Real-mocap folder (cmu/, bandai/) for the benchmarks that read real clips; "
            f"default ${MOCAP_ENV}, else generated motion."
        ),
    ] = None,
) -> None:
    """Benchmarks: prints a table, writes JSON (name, unit, value, baseline, ratio)."""
    from avatarsim.scripts.benchmarks import BENCHMARKS, run_benchmark

    json_out = json_out or Path("out/bench/bench.json")
    check_outputs(json_out=json_out)
    names = list(BENCHMARKS) if name is None else [name]
    unknown = [n for n in names if n not in BENCHMARKS]
    if unknown:
        raise AvatarsimError(
            f"unknown benchmark {unknown[0]!r}; available: {', '.join(BENCHMARKS)}"
        )
    mocap = mocap_dir(mocap)
    rows = [row for n in names for row in run_benchmark(n, quick=quick, mocap=mocap)]
    table = Table(title="avatarsim bench")
    for col in ("name", "unit", "value", "baseline", "ratio"):
        table.add_column(col, justify="right" if col != "name" else "left")
    for r in rows:
        base = "" if r.baseline is None else escape(f"{r.baseline:.4g} ({r.baseline_name})")
        ratio = "" if r.ratio is None else f"{r.ratio:.2f}x"
        table.add_row(escape(r.name), r.unit, f"{r.value:.4g}", base, ratio)
    console.print(table)
    # Benchmark inputs are fixed (seeded inside each module); the seed is recorded as asked.
    payload = {
        "seed": seed,
        "mocap": None if mocap is None else str(mocap),
        "benchmarks": [r.to_json() for r in rows],
    }
    emit_json(json_out, payload)


for _module in pkgutil.iter_modules(commands.__path__):
    importlib.import_module(f"avatarsim.scripts.commands.{_module.name}").register(app)


def main() -> None:  # pragma: no cover - console entry point
    app()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())

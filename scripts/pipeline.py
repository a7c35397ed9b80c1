"""The scenario runner: motion source -> humanoid -> physics checks -> pictures -> results.

Stages live in :mod:`scripts.stages` (one module each, with the metrics it produces), so a new
capability adds a module there; thresholds naming unknown metrics are rejected before anything
runs, and nothing is written for a scenario that does not validate.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape

from avatarsim.avatar_models.fileio import write_atomic, write_json
from avatarsim.scripts.report_html import render_report
from avatarsim.scripts.results import ThresholdResult, atomic_dir, junit_xml, versions
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Scenario, ScenarioError
from avatarsim.scripts.scenario_identity import scenario_hash
from avatarsim.scripts.stages import STAGES, physics
from avatarsim.sim.thresholds import ConfigError
from avatarsim.synthesis.methods import METHODS

METRICS: dict[str, str] = {k: v for stage in STAGES for k, v in stage.METRICS.items()}


def produced_metrics(stage, scenario: Scenario) -> set[str]:
    """The metrics ``stage`` produces for ``scenario`` (all of its ``METRICS`` unless it says)."""
    return stage.metrics_for(scenario) if hasattr(stage, "metrics_for") else set(stage.METRICS)


def validate(scenario: Scenario) -> None:
    """Everything about a scenario that can be checked before running it."""
    methods = scenario.synthesis.methods if scenario.synthesis is not None else ()
    unknown_methods = [m for m in methods if m not in METHODS]
    if unknown_methods:  # before the motion, body and physics stages, not after them
        raise ScenarioError(
            f"unknown synthesis method(s) {unknown_methods}; known: {', '.join(METHODS)}"
        )
    physics_keys = set(physics.METRICS)
    misplaced = sorted(set(scenario.thresholds) & physics_keys)
    if misplaced:
        raise ScenarioError(f"set physics thresholds {misplaced} in [physics], not [thresholds]")
    unknown = sorted(set(scenario.thresholds) - set(METRICS))
    if unknown:
        raise ScenarioError(
            f"thresholds name unknown metric(s) {unknown}; known: {sorted(METRICS)}"
        )
    produced = set().union(*(produced_metrics(stage, scenario) for stage in STAGES))
    idle = sorted(set(scenario.thresholds) - produced)
    if idle:
        raise ScenarioError(
            f"thresholds name metric(s) {idle} that this scenario does not produce "
            "(enable the stage or method that measures them)"
        )
    checked = set(scenario.thresholds) | set(physics.METRICS)
    unchecked = sorted(set(scenario.expect_fail) - checked)
    if unchecked:
        raise ScenarioError(
            f"expect_fail names {unchecked}, which are not checks of this scenario; checks: "
            f"its [thresholds] and the physics checks {sorted(physics.METRICS)}"
        )
    try:
        physics.config(scenario.physics)
    except ConfigError as exc:  # re-raised as the scenario's problem
        raise ScenarioError(f"[physics]: {exc}") from exc


def check_ready(scenario: Scenario) -> None:
    """Refuses, before any stage runs, a scenario whose methods cannot be built yet (e.g.
    ``controllerpose`` without a trained model), saying what to do. Apart from
    :func:`validate`: a scenario file is valid before its model is trained."""
    methods = scenario.synthesis.methods if scenario.synthesis is not None else ()
    missing = [f"{m}: {why}" for m in methods if (why := METHODS[m].missing()) is not None]
    if missing:
        raise ScenarioError(f"{scenario.name} cannot run yet: {'; '.join(missing)}")


def run_scenario(
    scenario: Scenario, out_dir: Path, console: Console | None = None
) -> dict[str, Any]:
    """Run every stage, evaluate thresholds, write results.json and junit.xml into ``out_dir``."""
    validate(scenario)
    check_ready(scenario)
    console = console or Console(stderr=True)
    with atomic_dir(out_dir, "run") as partial:
        return _run_stages(scenario, partial, console)


def _run_stages(scenario: Scenario, out_dir: Path, console: Console) -> dict[str, Any]:
    ctx = RunContext(scenario, out_dir, console)
    timings: dict[str, float] = {}
    start = time.perf_counter()
    for stage in STAGES:
        name = stage.__name__.rsplit(".", 1)[-1]
        t0 = time.perf_counter()
        with console.status(f"[bold]{escape(scenario.name)}[/]: {name}"):
            stage.run(ctx)
        timings[name] = round(time.perf_counter() - t0, 3)
        console.log(f"{name} done in {timings[name]:.2f} s")
    checks = [
        dataclasses.replace(c, expected_fail=c.name in scenario.expect_fail)
        for c in [ThresholdResult(k, ctx.metrics[k], t) for k, t in scenario.thresholds.items()]
        + ctx.checks
    ]
    passed = all(c.passed for c in checks)
    results = {
        "scenario": scenario.name,
        "scenario_path": scenario.path,
        "passed": passed,
        "checks": [c.to_json() for c in checks],
        "metrics": ctx.metrics,
        "seeds": {"scenario": scenario.seed},
        "scenario_hash": scenario_hash(scenario),
        **ctx.info,
        "outputs": {
            **ctx.outputs,
            "results_json": "results.json",
            "junit_xml": "junit.xml",
            "report_html": "report.html",
        },
        "timings_s": timings,
        "versions": versions(),
    }
    write_atomic(
        out_dir / "junit.xml", junit_xml(scenario.name, checks, time.perf_counter() - start)
    )
    write_atomic(out_dir / "report.html", render_report(results, out_dir))
    write_json(out_dir / "results.json", results)
    return results

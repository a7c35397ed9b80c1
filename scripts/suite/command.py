"""``avatarsim run PATH...`` in suite mode: check everything, run, compare, write the suite.

Order matters for CI: every input (scenario files, ``--workers``, ``--baseline`` and the
output paths) is checked before the first scenario starts (exit 2); the suite folder is
written atomically (:func:`scripts.results.atomic_dir`), then the baseline when asked.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.fileio import write_atomic, write_json
from avatarsim.scripts.results import atomic_dir, versions
from avatarsim.scripts.scenario_identity import scenario_hash
from avatarsim.scripts.suite.discovery import SuiteEntry, load_suite
from avatarsim.scripts.suite.index_html import render_index
from avatarsim.scripts.suite.junit import suite_junit
from avatarsim.scripts.suite.regression import (
    BaselineEntry,
    baseline_file,
    check_baseline,
    compare,
    load_baseline,
)
from avatarsim.scripts.suite.runner import STATUSES, Outcome, run_suite

MAX_WORKERS = 256
COLOURS = {"passed": "green", "failed": "red", "error": "red", "skipped": "dim"}


@dataclass(frozen=True)
class SuiteOptions:
    """The ``run`` command's suite options (see ``avatarsim run --help``)."""

    workers: int = 1
    fail_fast: bool = False
    pattern: str | None = None
    baseline: Path | None = None
    update_baseline: bool = False
    seed: int | None = None


def check_options(options: SuiteOptions) -> None:
    if not 1 <= options.workers <= MAX_WORKERS:
        raise AvatarsimError(f"--workers must be 1-{MAX_WORKERS}, got {options.workers}")
    if options.update_baseline and options.baseline is None:
        raise AvatarsimError("--update-baseline needs --baseline PATH (where to write it)")
    if options.update_baseline and baseline_file(options.baseline).exists():
        load_baseline(options.baseline)  # replaced only when it is a baseline (a results.json)


def prepare(
    paths: Sequence[Path], options: SuiteOptions
) -> tuple[list[SuiteEntry], dict[str, BaselineEntry]]:
    """The checked scenarios and the baseline to compare with (empty when none or when it
    is being replaced). Raises before anything runs."""
    check_options(options)
    entries = load_suite(paths, options.pattern, options.seed)
    if options.baseline is None or options.update_baseline:
        return entries, {}
    baseline = load_baseline(options.baseline)
    check_baseline(baseline, [e.scenario for e in entries], baseline_file(options.baseline))
    return entries, baseline


def scenario_record(outcome: Outcome, baseline: dict[str, BaselineEntry]) -> dict[str, Any]:
    """One scenario in the suite's results.json (its own results.json has everything else)."""
    sc, results = outcome.entry.scenario, outcome.results or {}
    metrics = results.get("metrics")
    stored = baseline.get(outcome.name)
    rows = []
    if stored is not None and metrics is not None:
        rows = [c.to_json() for c in compare(stored.metrics, metrics, sc.regression)]
    status = outcome.status
    if status == "passed" and any(r["regressed"] for r in rows):
        status = "failed"
    if stored is None and baseline and metrics is not None:
        message = "no baseline for this scenario: not compared"
    else:
        message = outcome.message
    return {
        "name": outcome.name,
        "path": sc.path,
        "status": status,
        "message": message,
        "seeds": {"scenario": sc.seed},
        "scenario_hash": scenario_hash(sc),
        "checks": results.get("checks", []),
        "regression": rows,
        "metrics": metrics,
        "report": f"{outcome.name}/report.html" if results else None,
        "time_s": round(outcome.time_s, 3),
    }


def suite_results(records: list[dict[str, Any]], baseline: Path | None) -> dict[str, Any]:
    counts = {status: sum(r["status"] == status for r in records) for status in STATUSES}
    counts["regressions"] = sum(row["regressed"] for r in records for row in r["regression"])
    counts["improvements"] = sum(row["improved"] for r in records for row in r["regression"])
    return {
        "suite": True,
        "passed": counts["failed"] == 0 and counts["error"] == 0,
        "counts": counts,
        "baseline": None if baseline is None else str(baseline),
        "scenarios": records,
        "outputs": {
            "junit_xml": "junit.xml",
            "results_json": "results.json",
            "index_html": "index.html",
        },
        "versions": versions(),
    }


def run_paths(
    paths: Sequence[Path], out: Path, options: SuiteOptions, console: Console
) -> dict[str, Any]:
    """Check, run and report a suite into ``out``; the suite's results.json as a dict."""
    entries, baseline = prepare(paths, options)
    console.print(f"suite: {len(entries)} scenario(s), {options.workers} worker(s)")

    def show(outcome: Outcome) -> None:
        mark = f"[{COLOURS[outcome.status]}]{outcome.status}[/]"
        console.print(f"  {escape(outcome.name)}: {mark} ({outcome.time_s:.1f} s)")

    with atomic_dir(out, "run") as partial:
        outcomes = run_suite(entries, partial, options.workers, options.fail_fast, show)
        records = [scenario_record(o, baseline) for o in outcomes]
        results = suite_results(records, options.baseline)
        write_atomic(partial / "junit.xml", suite_junit(records))
        write_atomic(partial / "index.html", render_index(results))
        write_json(partial / "results.json", results)
    if options.update_baseline:
        file = baseline_file(options.baseline)
        file.parent.mkdir(parents=True, exist_ok=True)
        write_json(file, results)
        console.print(f"baseline written to {escape(str(file))}")
    return results


def print_summary(results: dict[str, Any], out: Path, console: Console) -> None:
    """A table of the suite's scenarios: status, failed checks, regressions."""
    table = Table(title="suite")
    for col in ("scenario", "status", "checks failed", "regressions"):
        table.add_column(col)
    for sc in results["scenarios"]:
        failed = sum(not c["passed"] for c in sc["checks"])
        worse = sum(r["regressed"] for r in sc["regression"])
        status = f"[{COLOURS[sc['status']]}]{sc['status']}[/]"
        table.add_row(escape(sc["name"]), status, str(failed), str(worse))
    console.print(table)
    console.print(f"suite results in {escape(str(out))}/ (junit.xml, results.json, index.html)")

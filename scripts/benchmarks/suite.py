"""Scenario suite throughput: ``scripts/scenarios/smoke`` with 1 and with 2 workers.

Rows: the suite's wall time with 1 worker, with 2 (baseline: 1 worker, so the ratio is the
time fraction), the speed-up (baseline: the 1.7x aimed for on 2 cores), and the overhead per
scenario beyond its own stages, in core-seconds: ``(workers * wall - sum of stage times) / n``
(worker start-up, imports, results and reports, idle cores at the end). ``quick``: the two
shortest smoke scenarios only.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from avatarsim.scripts.benchmarks import BenchRow
from avatarsim.scripts.suite.discovery import load_suite
from avatarsim.scripts.suite.runner import run_suite

SMOKE = Path(__file__).resolve().parents[1] / "scenarios" / "smoke"
QUICK = ("walk_physics.toml", "sunk_feet.toml")
AIM_SPEEDUP = 1.7


def _timed(entries, workers: int) -> tuple[float, float]:
    """(wall seconds, seconds spent in stages) of one suite run."""
    with tempfile.TemporaryDirectory(prefix="avatarsim-bench-suite-") as tmp:
        t0 = time.perf_counter()
        outcomes = run_suite(entries, Path(tmp), workers)
        wall = time.perf_counter() - t0
    stages = sum(sum(o.results["timings_s"].values()) for o in outcomes if o.results)
    return wall, stages


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    paths = [SMOKE / f for f in QUICK] if quick else [SMOKE]
    entries = load_suite(paths)
    n = len(entries)
    wall1, stages1 = _timed(entries, 1)
    wall2, stages2 = _timed(entries, 2)
    note = f"{n} smoke scenarios"
    return [
        BenchRow("suite_smoke_1_worker", "s", wall1, note=note),
        BenchRow("suite_smoke_2_workers", "s", wall2, wall1, "1 worker", note),
        BenchRow("suite_smoke_speedup_2_workers", "x", wall1 / wall2, AIM_SPEEDUP, "aim", note),
        BenchRow("suite_overhead_per_scenario_1_worker", "core-s", (wall1 - stages1) / n),
        BenchRow("suite_overhead_per_scenario_2_workers", "core-s", (2 * wall2 - stages2) / n),
    ]

"""The runner: outcomes in suite order whatever the workers, identical results, fail-fast."""

from __future__ import annotations

import json

import avatarsim.scripts.suite.runner as runner
from avatarsim.scripts.suite.discovery import load_suite
from avatarsim.scripts.suite.regression import metric_kind
from tests.scripts.suite.conftest import write_scenario


def comparable(results: dict) -> dict:
    """A scenario's results without what measures the machine (timings, versions)."""
    metrics = {k: v for k, v in results["metrics"].items() if k == "frames" or metric_kind(k)}
    return {"checks": results["checks"], "metrics": metrics, "hash": results["scenario_hash"]}


def test_results_are_identical_with_one_or_two_workers(three_scenarios, three_suite, tmp_path):
    out2, _ = three_suite
    outcomes = runner.run_suite(load_suite([three_scenarios]), tmp_path, workers=1)
    assert [o.name for o in outcomes] == ["fail", "pass", "sunk"]
    for o in outcomes:
        two = json.loads((out2 / o.name / "results.json").read_text())
        assert comparable(o.results) == comparable(two)


def test_fail_fast_stops_after_the_first_failure(tmp_path, monkeypatch):
    for name in ("a", "b", "c"):
        write_scenario(tmp_path / "s", name)
    ran = []

    def fake(scenario, out_dir, console):
        ran.append(scenario.name)
        return {"passed": scenario.name != "a"}

    monkeypatch.setattr(runner, "run_scenario", fake)
    outcomes = runner.run_suite(load_suite([tmp_path / "s"]), tmp_path / "o", fail_fast=True)
    assert ran == ["a"]
    assert [o.status for o in outcomes] == ["failed", "skipped", "skipped"]
    assert outcomes[1].message == "not run: --fail-fast after a failed"
    outcomes = runner.run_suite(load_suite([tmp_path / "s"]), tmp_path / "o")
    assert [o.status for o in outcomes] == ["failed", "passed", "passed"]


def test_an_error_in_one_scenario_is_its_outcome_not_the_suites(tmp_path, monkeypatch):
    write_scenario(tmp_path / "s", "a")
    write_scenario(tmp_path / "s", "b")

    def fake(scenario, out_dir, console):
        if scenario.name == "a":
            raise ZeroDivisionError("a bug")
        return {"passed": True}

    monkeypatch.setattr(runner, "run_scenario", fake)
    a, b = runner.run_suite(load_suite([tmp_path / "s"]), tmp_path / "o")
    assert (a.status, a.message) == ("error", "internal error: ZeroDivisionError: a bug")
    assert b.status == "passed"

"""``avatarsim run PATH...`` as a suite: JUnit counts and exit codes, XSD-valid JUnit,
regressions against a baseline, and bad suites refused (exit 2) before anything runs."""

from __future__ import annotations

import dataclasses
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import avatarsim.scripts.stages.synthesis as synthesis_stage
import avatarsim.scripts.suite.runner as runner
from avatarsim.scripts.scenario import load_scenario
from avatarsim.scripts.scenario_identity import scenario_hash
from avatarsim.sim import corrupt
from tests.conftest import require_module
from tests.scripts.suite.conftest import invoke, write_scenario

XSD = Path(__file__).resolve().parents[2] / "data" / "jenkins-junit.xsd"


def validate_junit(path: Path) -> None:
    xmlschema = require_module("xmlschema")
    xmlschema.XMLSchema(XSD).validate(path)


def test_three_scenarios_give_the_right_junit_and_exit_code(three_suite):
    out, exit_code = three_suite
    assert exit_code == 1  # one threshold failed
    root = ET.parse(out / "junit.xml").getroot()
    suites = {s.get("name"): s for s in root.iter("testsuite")}
    # Files in name order, whichever worker finished first.
    assert list(suites) == ["fail", "pass", "sunk"]
    assert [suites[n].get("failures") for n in suites] == ["1", "0", "0"]
    failed = [c for c in suites["fail"].iter("testcase") if c.find("failure") is not None]
    assert [c.get("name") for c in failed] == ["frames"]
    assert failed[0].find("failure").get("message") == "frames = 91, threshold <= 10"
    sunk = {c.get("name"): c for c in suites["sunk"].iter("testcase")}
    assert "failed as expected" in sunk["penetration_cm_p95"].find("system-out").text
    assert root.get("failures") == "1"
    assert root.get("tests") == str(sum(int(s.get("tests")) for s in suites.values()))
    for junit in [out / "junit.xml", *(out / n / "junit.xml" for n in suites)]:
        validate_junit(junit)
    results = json.loads((out / "results.json").read_text())
    assert results["counts"] == dict(passed=2, failed=1, skipped=0, error=0) | {
        "regressions": 0,
        "improvements": 0,
    }
    assert [s["status"] for s in results["scenarios"]] == ["failed", "passed", "passed"]
    index = (out / "index.html").read_text()
    assert all(f'href="{n}/report.html"' in index for n in suites)
    assert all((out / n / "report.html").is_file() for n in suites)


IK_ONLY = '[devices]\nnoise = "none"\n[synthesis]\nmethods = ["ik"]'


def test_regression_flags_exactly_the_worse_metrics(tmp_path, monkeypatch):
    """A worse IK (noise on its output root) against a baseline of the plain one: every
    metric of its output gets worse, nothing measured before synthesis changes."""
    folder = tmp_path / "suite"
    write_scenario(folder, "ik", tables=IK_ONLY)
    write_scenario(folder, "walk")
    base = tmp_path / "baseline.json"
    first = invoke(folder, "--out", tmp_path / "o1", "--baseline", base, "--update-baseline")
    assert first.exit_code == 0, first.output
    same = invoke(folder, "--out", tmp_path / "o2", "--baseline", base)
    assert same.exit_code == 0, same.output
    rerun = json.loads((tmp_path / "o2" / "results.json").read_text())
    assert rerun["counts"]["regressions"] == 0 and rerun["counts"]["improvements"] == 0
    rows = [r for sc in rerun["scenarios"] for r in sc["regression"]]
    assert rows and not any(r["regressed"] or r["improved"] for r in rows)

    make = synthesis_stage.make_synthesizer

    def worse(method, inputs):
        synth = make(method, inputs)
        plain = synth.run
        synth.run = lambda stream: corrupt.add_jitter(plain(stream), np.random.default_rng(0), 0.05)
        return synth

    monkeypatch.setattr(synthesis_stage, "make_synthesizer", worse)
    bad = invoke(folder, "--out", tmp_path / "o3", "--baseline", base)
    assert bad.exit_code == 1, bad.output
    results = json.loads((tmp_path / "o3" / "results.json").read_text())
    flagged = {
        (sc["name"], r["metric"])
        for sc in results["scenarios"]
        for r in sc["regression"]
        if r["regressed"]
    }
    # Zero-mean noise can only raise a mean distance (the norm is convex), and its vertical
    # part sinks the feet at the 95th percentile; nothing measured before synthesis moves.
    # Stance-foot skating falls instead (noisy feet no longer count as planted): an
    # improvement, reported and never failed.
    worse_metrics = {f"ik_err_cm_{g}" for g in ("hands", "upper", "lower", "full")}
    worse_metrics |= {"ik_penetration_cm_p95"}
    assert flagged == {("ik", m) for m in worse_metrics}
    improved = {
        r["metric"] for sc in results["scenarios"] for r in sc["regression"] if r["improved"]
    }
    assert improved == {"ik_skate_cm_s_median"}
    root = ET.parse(tmp_path / "o3" / "junit.xml").getroot()
    failing = {c.get("name") for c in root.iter("testcase") if c.find("failure") is not None}
    assert failing == {f"regression:{m}" for m in worse_metrics}
    validate_junit(tmp_path / "o3" / "junit.xml")


@pytest.fixture
def no_runs(monkeypatch):
    """Fails the test if any scenario starts."""
    calls = []
    monkeypatch.setattr(runner, "run_scenario", lambda *a, **k: calls.append(a))
    yield
    assert not calls, "a scenario ran before the suite was refused"


def refused(result, out: Path, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    assert not out.exists()
    for fragment in fragments:
        assert fragment in " ".join(result.output.split())


def test_two_scenarios_with_one_name_are_refused(tmp_path, no_runs):
    write_scenario(tmp_path / "s", "twin", file="a")
    write_scenario(tmp_path / "s", "twin", file="b")
    refused(invoke(tmp_path / "s", "--out", tmp_path / "o"), tmp_path / "o", "named 'twin'")


def test_an_unknown_key_in_one_of_ten_files_is_refused(tmp_path, no_runs):
    for i in range(10):
        write_scenario(tmp_path / "s", f"s{i}", motion="activty = 'run'" if i == 7 else "")
    refused(invoke(tmp_path / "s", "--out", tmp_path / "o"), tmp_path / "o", "s7.toml", "activty")


def test_a_baseline_from_another_scenario_version_is_refused(tmp_path, no_runs):
    path = write_scenario(tmp_path / "s", "walk")
    older = dataclasses.replace(
        load_scenario(path), motion=dataclasses.replace(load_scenario(path).motion, duration_s=2.0)
    )
    stored = {"name": "walk", "seeds": {"scenario": 1}, "scenario_hash": scenario_hash(older)}
    base = tmp_path / "baseline.json"
    base.write_text(json.dumps({"scenarios": [stored | {"metrics": {"frames": 181.0}}]}))
    result = invoke(tmp_path / "s", "--out", tmp_path / "o", "--baseline", base)
    refused(result, tmp_path / "o", "'walk'", "changed since the baseline", "--update-baseline")


def test_a_baseline_with_another_seed_is_refused(tmp_path, no_runs):
    path = write_scenario(tmp_path / "s", "walk")
    stored = {
        "name": "walk",
        "seeds": {"scenario": 5},
        "scenario_hash": scenario_hash(load_scenario(path)),
    }
    base = tmp_path / "baseline.json"
    base.write_text(json.dumps({"scenarios": [stored | {"metrics": {}}]}))
    result = invoke(tmp_path / "s", "--out", tmp_path / "o", "--baseline", base)
    refused(result, tmp_path / "o", "seed 5", "--update-baseline")


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_workers_below_one_are_refused(tmp_path, no_runs, workers):
    write_scenario(tmp_path / "s", "walk")
    refused(
        invoke(tmp_path / "s", "--out", tmp_path / "o", "--workers", workers),
        tmp_path / "o",
        "--workers",
    )


def test_update_baseline_needs_a_baseline_path(tmp_path, no_runs):
    write_scenario(tmp_path / "s", "walk")
    refused(
        invoke(tmp_path / "s", "--out", tmp_path / "o", "--update-baseline"),
        tmp_path / "o",
        "--baseline",
    )

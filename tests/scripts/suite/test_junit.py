"""The suite's JUnit: units in messages, counts per scenario, skipped and errored scenarios,
and the Jenkins/GitLab schema."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from avatarsim.scripts.suite.junit import check_message, metric_unit, suite_junit
from tests.conftest import require_module

XSD = Path(__file__).resolve().parents[2] / "data" / "jenkins-junit.xsd"


@pytest.mark.parametrize(
    "name, unit",
    [
        ("skate_cm_s_median", "cm/s"),
        ("skate_slide_cm_max", "cm"),
        ("penetration_cm_p95", "cm"),
        ("replay_error_mm_max", "mm"),
        ("jitter_m_s3_median", "m/s^3"),
        ("residual_force_bw_p95", "x body weight"),
        ("joint_limit_violation_frac", "fraction"),
        ("coolmoves_hand_corr_min", "Pearson r"),
        ("control_upright_s", "s"),
        ("kinect_fps_rendered", "frames/s"),
        ("frames", ""),
        ("control_fell", ""),
    ],
)
def test_units_come_from_the_metric_names(name, unit):
    assert metric_unit(name) == unit


def test_messages_give_value_threshold_and_unit():
    row = {"name": "penetration_cm_p95", "value": 7.25, "threshold": 5.0, "passed": False}
    assert check_message(row) == "penetration_cm_p95 = 7.25 cm, threshold <= 5 cm"
    row = {"name": "x_hand_corr_min", "value": 0.5, "threshold": ">= 0.9", "passed": False}
    assert check_message(row) == "x_hand_corr_min = 0.5 Pearson r, threshold >= 0.9 Pearson r"
    expected = {"name": "float_cm_p95", "value": 1.0, "threshold": 5.0, "passed": False}
    assert check_message(expected | {"expected_fail": True}).endswith("passed but expected to fail")


def record(name, status, checks=(), regression=(), message=""):
    return {
        "name": name,
        "status": status,
        "message": message,
        "time_s": 1.5,
        "checks": list(checks),
        "regression": list(regression),
    }


def test_counts_skips_errors_and_regressions(tmp_path):
    ok = {"name": "frames", "value": 9.0, "threshold": 10.0, "passed": True}
    bad = {"name": "float_cm_p95", "value": 9.0, "threshold": 5.0, "passed": False}
    worse = {"metric": "a_err_cm_full", "baseline": 1.0, "value": 3.0, "tolerance": 0.5}
    records = [
        record("a", "failed", [ok, bad], [worse | {"regressed": True, "improved": False}]),
        record("b", "skipped", message="motion file x is absent"),
        record("c", "error", message="internal error: boom"),
    ]
    text = suite_junit(records)
    root = ET.fromstring(text)
    suites = {s.get("name"): s for s in root.iter("testsuite")}
    assert [
        (s.get("tests"), s.get("failures"), s.get("errors"), s.get("skipped"))
        for s in suites.values()
    ] == [
        ("3", "2", "0", "0"),
        ("1", "0", "0", "1"),
        ("1", "0", "1", "0"),
    ]
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("5", "2", "1")
    names = [c.get("name") for c in suites["a"].iter("testcase")]
    assert names == ["frames", "float_cm_p95", "regression:a_err_cm_full"]
    assert suites["b"].find("testcase/skipped").get("message") == "motion file x is absent"
    (tmp_path / "junit.xml").write_text(text)
    require_module("xmlschema").XMLSchema(XSD).validate(tmp_path / "junit.xml")


def test_junitparser_reads_the_suite_junit(tmp_path):
    """A second, independent reader (junitparser) counts the same suites, cases and results."""
    junitparser = require_module("junitparser")
    ok = {"name": "frames", "value": 9.0, "threshold": 10.0, "passed": True}
    bad = {"name": "float_cm_p95", "value": 9.0, "threshold": 5.0, "passed": False}
    records = [
        record("a", "failed", [ok, bad]),
        record("b", "skipped", message="motion file x is absent"),
        record("c", "error", message="internal error: boom"),
    ]
    path = tmp_path / "junit.xml"
    path.write_text(suite_junit(records))
    suites = {s.name: s for s in junitparser.JUnitXml.fromfile(str(path))}
    assert sorted(suites) == ["a", "b", "c"]
    results = {
        (name, case.name): [type(r).__name__ for r in case.result]
        for name, suite in suites.items()
        for case in suite
    }
    assert results[("a", "frames")] == [] and results[("a", "float_cm_p95")] == ["Failure"]
    assert [r for (s, _), r in results.items() if s in "bc"] == [["Skipped"], ["Error"]]
    (skip,) = next(iter(suites["b"])).result
    assert skip.message == "motion file x is absent"
    (failure,) = next(c for c in suites["a"] if c.name == "float_cm_p95").result
    assert failure.message == "float_cm_p95 = 9 cm, threshold <= 5 cm"
    assert [(s.tests, s.failures, s.errors, s.skipped) for s in suites.values()] == [
        (2, 1, 0, 0),
        (1, 0, 0, 1),
        (1, 0, 1, 0),
    ]

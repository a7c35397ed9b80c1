"""Check rows: an expected failure passes when its threshold is missed, fails when met."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from avatarsim.scripts.results import ThresholdResult, junit_xml
from avatarsim.scripts.scenario import Threshold
from tests.conftest import require_module


def test_expected_failure_turns_the_verdict_round():
    missed = ThresholdResult("float_cm_p95", 15.0, Threshold(max=5.0), expected_fail=True)
    met = ThresholdResult("float_cm_p95", 1.0, Threshold(max=5.0), expected_fail=True)
    assert missed.passed and missed.to_json()["expected_fail"] is True
    assert not met.passed
    assert met.failure_message() == "1 is <= 5, but expected to fail"
    root = ET.fromstring(junit_xml("s", [missed, met]))
    assert root.get("failures") == "1"
    failed = [c.get("name") for c in root.iter("testcase") if c.find("failure") is not None]
    assert failed == ["float_cm_p95"] and len(list(root.iter("testcase"))) == 2


def test_a_plain_check_has_no_expected_fail_key():
    row = ThresholdResult("frames", 3.0, Threshold(max=5.0)).to_json()
    assert "expected_fail" not in row and row["passed"]


def test_junitparser_reads_a_scenario_junit(tmp_path):
    """A second, independent JUnit reader (junitparser) sees the same cases and verdicts."""
    junitparser = require_module("junitparser")
    checks = [
        ThresholdResult("penetration_cm_p95", 7.25, Threshold(max=5.0)),
        ThresholdResult("frames", 3.0, Threshold(max=5.0)),
    ]
    path = tmp_path / "junit.xml"
    path.write_text(junit_xml("demo", checks, time_s=2.5))
    xml = junitparser.JUnitXml.fromfile(str(path))
    (suite,) = list(xml) if isinstance(xml, junitparser.JUnitXml) else [xml]
    assert (suite.name, suite.tests, suite.failures, suite.time) == ("demo", 2, 1, 2.5)
    cases = {case.name: case for case in suite}
    assert cases["frames"].is_passed and cases["frames"].classname == "avatarsim.demo"
    (failure,) = cases["penetration_cm_p95"].result
    assert isinstance(failure, junitparser.Failure)
    assert "7.25" in failure.message and "5" in failure.message

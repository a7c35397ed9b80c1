"""The suite's JUnit XML: one ``<testsuite>`` per scenario, one ``<testcase>`` per check and
per compared metric (``regression:<metric>``), in the schema Jenkins and GitLab read
(``tests/data/jenkins-junit.xsd``). Failure messages give value, threshold and unit.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

# Metric name fragment -> unit, first match wins (names carry their unit, e.g. skate_cm_s).
UNITS = (
    ("_cm_s", "cm/s"),
    ("_m_s3", "m/s^3"),
    ("_cm", "cm"),
    ("_mm", "mm"),
    ("_bw", "x body weight"),
    ("_frac", "fraction"),
    ("_corr", "Pearson r"),
    ("_fps", "frames/s"),
    ("_x_real_time", "x real time"),
    ("_s", "s"),
)


def metric_unit(name: str) -> str:
    """The unit a metric's name states ('' for counts and 0/1 flags)."""
    return next((unit for key, unit in UNITS if f"{key}_" in f"{name}_"), "")


def _with_unit(value: float | None, unit: str) -> str:
    text = "NaN" if value is None else f"{value:.4g}"
    return f"{text} {unit}".strip()


def _threshold_text(threshold: Any, unit: str) -> str:
    if isinstance(threshold, int | float):
        return f"<= {_with_unit(threshold, unit)}"
    return f"{threshold} {unit}".strip()  # already "<= a and >= b"


def check_message(check: dict[str, Any]) -> str:
    """Value, threshold and unit of a check row of results.json, and its verdict."""
    unit = metric_unit(check["name"])
    value, threshold = _with_unit(check["value"], unit), _threshold_text(check["threshold"], unit)
    if check.get("expected_fail"):
        verdict = "failed as expected" if check["passed"] else "passed but expected to fail"
        return f"{check['name']} = {value}, threshold {threshold}: {verdict}"
    return f"{check['name']} = {value}, threshold {threshold}"


def regression_message(row: dict[str, Any]) -> str:
    unit = metric_unit(row["metric"])
    word = "worse" if row["regressed"] else "better" if row["improved"] else "within tolerance"
    return (
        f"{row['metric']} = {_with_unit(row['value'], unit)}, baseline "
        f"{_with_unit(row['baseline'], unit)}, tolerance {_with_unit(row['tolerance'], unit)}: "
        f"{word}"
    )


def _case(suite: ET.Element, scenario: str, name: str, time_s: float = 0.0) -> ET.Element:
    return ET.SubElement(
        suite, "testcase", classname=f"avatarsim.{scenario}", name=name, time=f"{time_s:.3f}"
    )


def _testsuite(record: dict[str, Any]) -> ET.Element:
    name = record["name"]
    suite = ET.Element("testsuite", name=name, time=f"{record['time_s']:.3f}")
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    if record["status"] in ("skipped", "error") and not record["checks"]:
        case = _case(suite, name, "scenario", record["time_s"])
        tag = record["status"]
        ET.SubElement(case, tag, message=record["message"])
        counts["tests"], counts["errors" if tag == "error" else "skipped"] = 1, 1
    for check in record["checks"]:
        case = _case(suite, name, check["name"])
        if not check["passed"]:
            ET.SubElement(case, "failure", message=check_message(check), type="threshold")
            counts["failures"] += 1
        elif check.get("expected_fail"):
            ET.SubElement(case, "system-out").text = check_message(check)
        counts["tests"] += 1
    for row in record["regression"]:
        case = _case(suite, name, f"regression:{row['metric']}")
        if row["regressed"]:
            ET.SubElement(case, "failure", message=regression_message(row), type="regression")
            counts["failures"] += 1
        elif row["improved"]:
            ET.SubElement(case, "system-out").text = regression_message(row)
        counts["tests"] += 1
    for key, n in counts.items():
        suite.set(key, str(n))
    return suite


def suite_junit(records: list[dict[str, Any]], name: str = "avatarsim") -> str:
    """The ``<testsuites>`` document of a suite's scenario records (its results.json's
    ``scenarios``: name, status, message, time_s, checks, regression)."""
    root = ET.Element("testsuites", name=name)
    suites = [_testsuite(r) for r in records]
    root.extend(suites)
    for key in ("tests", "failures", "errors"):
        root.set(key, str(sum(int(s.get(key)) for s in suites)))
    root.set("time", f"{sum(r['time_s'] for r in records):.3f}")
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"

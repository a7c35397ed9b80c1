"""Scenario validation: clear ScenarioErrors for bad files; thresholds; results files."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from avatarsim.scripts.results import ThresholdResult, junit_xml
from avatarsim.scripts.scenario import (
    DEFAULT_SCENARIO,
    ScenarioError,
    Threshold,
    load_scenario,
    parse_scenario,
)


def test_default_scenario_is_valid():
    sc = load_scenario(DEFAULT_SCENARIO)
    assert sc.motion.source == "builtin" and sc.thresholds


@pytest.mark.parametrize(
    "data, message",
    [
        ({"motoin": {}}, r"unknown key 'motoin' in \[top level\]; allowed: body, "),
        (
            {"motion": {"activty": "walk"}},
            r"unknown key 'activty' in \[motion\]; allowed: activity",
        ),
        ({"motion": {"fps": "fast"}}, "motion.fps must be a number"),
        ({"motion": {"duration_s": -1}}, "motion.duration_s must be > 0 and <= 600"),
        ({"motion": {"height_m": 175}}, "motion.height_m must be >= 1 and <= 2.5, got 175"),
        ({"body": {"mass_kg": 0}}, "body.mass_kg must be >= 10 and <= 300"),
        ({"seed": 1.5}, "seed must be an integer"),
        ({"thresholds": {"x": "big"}}, "must be a number"),
        ({"thresholds": {"x": {"maximum": 1}}}, "must be a number"),
        ({"control": {"seconds": 0}}, "control.seconds must be > 0"),
        ({"control": {"search": "yes"}}, "control.search must be a boolean"),
        ({"expect_fail": "frames"}, "expect_fail must be an array"),
        ({"regression": {"frames": -1}}, "tolerances must be finite numbers, 0 or more"),
        ({"regression": {"frames": "big"}}, "regression.frames must be a number"),
        ({"motion": {"corrupt": "melt"}}, "motion.corrupt must be one of"),
        ({"devices": {"latency_s": 5.0}}, "devices.latency_s must be >= 0 and <= 1"),
        ({"devices": {"dropouts_per_s": -1}}, "devices.dropouts_per_s must be >= 0 and <= 10"),
        ({"devices": {"kinect": "kinect-v9"}}, "devices.kinect must be one of"),
    ],
)
def test_invalid_scenarios_name_the_problem(data, message):
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(data)


def test_bad_toml_and_missing_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = [unclosed")
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scenario(bad)
    with pytest.raises(ScenarioError, match="does not exist"):
        load_scenario(tmp_path / "nope.toml")


def test_motion_path_is_relative_to_scenario(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('[motion]\nsource = "clips/walk.bvh"\n')
    assert load_scenario(f).motion.source == str(tmp_path / "clips" / "walk.bvh")


def test_threshold_semantics():
    assert Threshold(max=1.0).passes(1.0) and not Threshold(max=1.0).passes(1.01)
    assert Threshold(min=0.9).passes(0.95) and not Threshold(min=0.9).passes(0.5)
    assert not Threshold(max=1.0).passes(float("nan"))


def test_junit_xml_marks_failures():
    checks = [
        ThresholdResult("a", 0.5, Threshold(max=1.0)),
        ThresholdResult("b", 2.0, Threshold(max=1.0)),
    ]
    root = ET.fromstring(junit_xml("demo", checks))
    assert root.get("tests") == "2" and root.get("failures") == "1"
    cases = {c.get("name"): c for c in root.iter("testcase")}
    assert cases["a"].find("failure") is None
    assert "2" in cases["b"].find("failure").get("message")


def test_non_finite_thresholds_are_rejected():
    with pytest.raises(ScenarioError, match="finite"):
        parse_scenario({"thresholds": {"frames": float("nan")}})


def test_control_thresholds_need_the_control_stage():
    from avatarsim.scripts.pipeline import validate

    with pytest.raises(ScenarioError, match="does not produce"):
        validate(parse_scenario({"thresholds": {"control_fell": 0.0}}))
    validate(parse_scenario({"control": {}, "thresholds": {"control_fell": 0.0}}))


def test_an_unknown_method_is_rejected_before_the_run():
    # Regression: a typo in [synthesis] methods surfaced only after the motion, body, physics
    # and device stages had run.
    from avatarsim.scripts.pipeline import validate

    with pytest.raises(ScenarioError, match="unknown synthesis method.*nonsense"):
        validate(parse_scenario({"devices": {}, "synthesis": {"methods": ["ik", "nonsense"]}}))
    validate(parse_scenario({"devices": {}, "synthesis": {"methods": ["ik"]}}))

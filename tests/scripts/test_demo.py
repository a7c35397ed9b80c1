"""End to end: a short built-in scenario writes results, JUnit and pictures, and checks pass."""

from __future__ import annotations

import dataclasses
import json
import xml.etree.ElementTree as ET

import imageio.v3 as iio
import numpy as np
import pytest
from rich.console import Console

from avatarsim.scripts.pipeline import run_scenario
from avatarsim.scripts.scenario import DEFAULT_SCENARIO, ReportSpec, load_scenario


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    sc = load_scenario(DEFAULT_SCENARIO)
    sc = dataclasses.replace(
        sc,
        motion=dataclasses.replace(sc.motion, duration_s=1.5),
        report=ReportSpec(picture_frames=3, gif=False),
    )
    out = tmp_path_factory.mktemp("demo")
    return out, run_scenario(sc, out, Console(quiet=True))


def test_results_follow_the_contract(short_run):
    out, results = short_run
    on_disk = json.loads((out / "results.json").read_text())
    assert on_disk["scenario"] == "default" and on_disk["seeds"] == {"scenario": 0}
    names = {c["name"] for c in on_disk["checks"]}
    assert {"replay_error_mm_max", "penetration_cm_p95", "skate_cm_s_median"} <= names
    for c in on_disk["checks"]:
        assert {"name", "value", "threshold", "passed"} <= set(c)
    assert on_disk["motion"]["frames"] == 136  # 1.5 s at 90 fps, both ends included
    root = ET.parse(out / "junit.xml").getroot()
    assert int(root.get("tests")) == len(on_disk["checks"])
    assert int(root.get("failures")) == sum(not c["passed"] for c in on_disk["checks"])


def test_replay_is_exact_and_on_the_floor(short_run):
    _, results = short_run
    assert results["metrics"]["replay_error_mm_max"] < 1e-3
    assert results["passed"], results["checks"]


def test_strip_shows_a_body(short_run):
    out, _ = short_run
    strip = iio.imread(out / "strip.png")
    assert strip.shape[0] == 400 and strip.shape[1] == 3 * 320
    # The body is rendered in its own colour: the middle of each panel differs from the
    # plain background at the panel's top corner.
    panels = np.split(strip[..., :3].astype(float), 3, axis=1)
    for p in panels:
        centre = p[150:300, 120:200].reshape(-1, 3)
        corner = p[:20, :20].reshape(-1, 3).mean(0)
        assert np.mean(np.linalg.norm(centre - corner, axis=1) > 40) > 0.1


def test_html_report_is_self_contained(short_run):
    out, results = short_run
    page = (out / "report.html").read_text()
    assert "<h1>Scenario <code>default</code>" in page
    for check in results["checks"]:
        assert check["name"] in page
    # Pictures are inlined, so the page works when mailed or archived on its own.
    assert page.count('src="data:image/png;base64,') >= 2 and 'src="out' not in page

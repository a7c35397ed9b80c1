"""Regression against a baseline: direction, tolerances, NaN, baseline formats, refusals."""

from __future__ import annotations

import json

import pytest

from avatarsim.scripts.scenario import ScenarioError, load_scenario
from avatarsim.scripts.scenario_identity import scenario_hash
from avatarsim.scripts.suite.regression import (
    BaselineEntry,
    baseline_file,
    check_baseline,
    compare,
    load_baseline,
    metric_kind,
)
from tests.scripts.suite.conftest import write_scenario


@pytest.mark.parametrize(
    "name, kind",
    [
        ("coolmoves_err_cm_full", "accuracy"),
        ("replay_error_mm_max", "accuracy"),
        ("ik_hand_corr_min", "rate"),
        ("vr_valid_frac", "rate"),
        ("control_fell", "rate"),
        ("skate_cm_s_median", "physics"),
        ("control_upright_s", "physics"),
        ("frames", None),
        ("fisheye_fps_rendered", None),
        ("control_x_real_time", None),
    ],
)
def test_metric_kinds(name, kind):
    assert metric_kind(name) == kind


def by_name(rows):
    return {r.metric: r for r in rows}


def test_worse_is_higher_for_errors_and_lower_for_correlations():
    base = {"coolmoves_err_cm_full": 5.0, "coolmoves_hand_corr_min": 0.95}
    rows = by_name(
        compare(base, {"coolmoves_err_cm_full": 5.6, "coolmoves_hand_corr_min": 0.92}, {})
    )
    assert rows["coolmoves_err_cm_full"].regressed  # 0.6 cm > 0.5 cm
    assert rows["coolmoves_hand_corr_min"].regressed  # 0.03 > 0.02
    rows = by_name(
        compare(base, {"coolmoves_err_cm_full": 4.0, "coolmoves_hand_corr_min": 0.99}, {})
    )
    assert all(r.improved and not r.regressed for r in rows.values())
    rows = by_name(
        compare(base, {"coolmoves_err_cm_full": 5.4, "coolmoves_hand_corr_min": 0.94}, {})
    )
    assert not any(r.improved or r.regressed for r in rows.values())


def test_physics_tolerance_is_relative_above_its_floor_and_overrides_win():
    base = {"skate_cm_s_median": 30.0, "penetration_cm_p95": 1.0}
    rows = by_name(compare(base, {"skate_cm_s_median": 32.9, "penetration_cm_p95": 1.4}, {}))
    assert not rows["skate_cm_s_median"].regressed  # within 10 % of 30
    assert not rows["penetration_cm_p95"].regressed  # within the 0.5 cm floor
    rows = by_name(compare(base, {"skate_cm_s_median": 32.9}, {"skate_cm_s_median": 1.0}))
    assert rows["skate_cm_s_median"].regressed and set(rows) == {"skate_cm_s_median"}


def test_a_value_that_became_nan_regresses_and_timings_are_not_compared():
    base = {"coolmoves_err_cm_full": 5.0, "kinect_fps_rendered": 100.0, "frames": 90.0}
    rows = compare(
        base, {"coolmoves_err_cm_full": None, "kinect_fps_rendered": 1.0, "frames": 1}, {}
    )
    assert [(r.metric, r.regressed) for r in rows] == [("coolmoves_err_cm_full", True)]


def test_baselines_load_from_a_suite_a_single_run_or_a_folder(tmp_path):
    run = {"scenario": "a", "seeds": {"scenario": 3}, "scenario_hash": "h", "metrics": {"x": 1.0}}
    (tmp_path / "single").mkdir()
    (tmp_path / "single" / "results.json").write_text(json.dumps(run))
    suite = {"scenarios": [run | {"name": "b"}, {"name": "skipped", "metrics": None}]}
    (tmp_path / "suite.json").write_text(json.dumps(suite))
    assert load_baseline(tmp_path / "single")["a"].seed == 3
    loaded = load_baseline(tmp_path / "suite.json")
    assert set(loaded) == {"b"} and loaded["b"].metrics == {"x": 1.0}
    assert baseline_file(tmp_path / "new") == tmp_path / "new" / "results.json"


def test_a_baseline_without_hashes_or_unreadable_is_refused(tmp_path):
    (tmp_path / "old.json").write_text(json.dumps({"scenario": "a", "metrics": {}}))
    with pytest.raises(ScenarioError, match="--update-baseline"):
        load_baseline(tmp_path / "old.json")
    with pytest.raises(ScenarioError, match="cannot read"):
        load_baseline(tmp_path / "absent.json")


def test_check_baseline_names_the_scenario_and_ignores_new_ones(tmp_path):
    sc = load_scenario(write_scenario(tmp_path, "a"))
    check_baseline(
        {}, [sc], tmp_path
    )  # a scenario new to the baseline: compared later, not refused
    check_baseline({"a": BaselineEntry(sc.seed, scenario_hash(sc), {})}, [sc], tmp_path)
    with pytest.raises(ScenarioError, match="scenario 'a'.*changed since the baseline"):
        check_baseline({"a": BaselineEntry(sc.seed, "0" * 16, {})}, [sc], tmp_path)

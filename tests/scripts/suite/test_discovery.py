"""Suite discovery: files and folders, every file checked before any runs, -k selection."""

from __future__ import annotations

from pathlib import Path

import pytest

from avatarsim.avatar_models.mocap_dir import MOCAP_ENV
from avatarsim.scripts.scenario import ScenarioError
from avatarsim.scripts.suite.discovery import load_suite, scenario_files, selected
from tests.scripts.suite.conftest import write_scenario

SHIPPED = Path(__file__).resolve().parents[3] / "scripts" / "scenarios"


def test_folders_are_searched_recursively_in_name_order_each_file_once(tmp_path):
    b = write_scenario(tmp_path / "x", "b")
    a = write_scenario(tmp_path / "x" / "deeper", "a")
    c = write_scenario(tmp_path, "c")
    (tmp_path / "x" / "notes.txt").write_text("not a scenario")
    assert scenario_files([tmp_path / "x", c, b]) == [b, a, c]


def test_an_empty_folder_or_a_missing_path_is_bad_input(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ScenarioError, match="holds no scenario"):
        scenario_files([tmp_path / "empty"])
    with pytest.raises(ScenarioError, match="does not exist"):
        scenario_files([tmp_path / "nope.toml"])


def test_every_bad_file_is_named_in_one_message(tmp_path):
    write_scenario(tmp_path, "good")
    write_scenario(tmp_path, "bad1", motion="activty = 'run'")
    write_scenario(tmp_path, "bad2", tables="[thresholds]\nno_such_metric = 1")
    with pytest.raises(ScenarioError, match="2 bad scenario file") as err:
        load_suite([tmp_path])
    assert "bad1.toml" in str(err.value) and "bad2.toml" in str(err.value)


def test_expect_fail_must_name_a_check(tmp_path):
    write_scenario(tmp_path, "x", top='expect_fail = ["frames"]')
    with pytest.raises(ScenarioError, match="not checks of this scenario"):
        load_suite([tmp_path])


@pytest.mark.parametrize("name", ["a/b", "junit.xml", "..", "-x"])
def test_a_name_must_be_a_folder_name(tmp_path, name):
    write_scenario(tmp_path, name, file="s")
    with pytest.raises(ScenarioError, match="cannot name an output folder"):
        load_suite([tmp_path])


def test_a_missing_motion_file_is_bad_unless_it_may_be_skipped(tmp_path):
    missing = 'source = "absent.bvh"'
    path = write_scenario(tmp_path / "a", "real", motion=missing)
    text = path.read_text().replace('activity = "walk"\n', "")  # a file has no activity
    path.write_text(text)
    with pytest.raises(ScenarioError, match="absent.bvh does not exist"):
        load_suite([tmp_path / "a"])
    (tmp_path / "a" / "real.toml").write_text(
        text.replace(missing, f"{missing}\nskip_if_absent = true")
    )
    (entry,) = load_suite([tmp_path / "a"])
    assert "absent" in entry.skip_reason


@pytest.mark.mocap
def test_shipped_real_clip_scenarios_read_the_mocap_folder(mocap_dir, monkeypatch):
    """``mocap:`` sources resolve inside $AVATARSIM_MOCAP, wherever the scenario file is."""
    monkeypatch.setenv(MOCAP_ENV, str(mocap_dir))
    entries = load_suite([SHIPPED / "methods", SHIPPED / "devices"])
    real = [e for e in entries if e.scenario.motion.skip_if_absent]
    assert len(real) >= 5
    for entry in real:
        assert entry.skip_reason is None
        source = Path(entry.scenario.motion.source)
        assert source.is_file() and source.is_relative_to(mocap_dir), source


def test_shipped_real_clip_scenarios_skip_without_a_mocap_folder(monkeypatch):
    monkeypatch.delenv(MOCAP_ENV, raising=False)
    entries = load_suite([SHIPPED / "methods", SHIPPED / "devices"])
    skipped = [e for e in entries if e.skip_reason]
    assert skipped and all(MOCAP_ENV in e.skip_reason for e in skipped)
    assert all(e.scenario.motion.source == "builtin" for e in entries if not e.skip_reason)


def test_a_mocap_source_that_may_not_be_skipped_needs_the_folder(tmp_path, monkeypatch):
    monkeypatch.delenv(MOCAP_ENV, raising=False)
    path = write_scenario(tmp_path, "real", motion='source = "mocap:cmu/16_35.bvh"')
    path.write_text(path.read_text().replace('activity = "walk"\n', ""))
    with pytest.raises(ScenarioError, match=MOCAP_ENV):
        load_suite([tmp_path])


def test_k_selects_by_substring_or_glob_and_refuses_an_empty_selection(tmp_path):
    for name in ("smoke-walk", "smoke-run", "methods-walk"):
        write_scenario(tmp_path, name)
    entries = load_suite([tmp_path])
    assert [e.name for e in selected(entries, "walk")] == ["methods-walk", "smoke-walk"]
    assert [e.name for e in selected(entries, "smoke-*")] == ["smoke-run", "smoke-walk"]
    with pytest.raises(ScenarioError, match="selects no scenario"):
        selected(entries, "swim")


def test_seed_overrides_every_scenario(tmp_path):
    write_scenario(tmp_path, "a")
    (entry,) = load_suite([tmp_path], seed=7)
    assert entry.scenario.seed == 7


def test_every_shipped_suite_is_valid_with_unique_names():
    """scripts/scenarios/ as one suite: every file checks, no two share a name."""
    entries = load_suite([SHIPPED])
    folders = {Path(e.scenario.path).parent.name for e in entries}
    assert {"smoke", "methods", "devices", "physics"} <= folders

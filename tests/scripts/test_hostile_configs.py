"""Hostile configs (values of the wrong type or size, and ``check --config``):
each exits 2 at once through the CLI with one line naming the field, and writes nothing."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import tomli_w
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import save_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.cli import app
from tests.scripts.dataset.builders import TINY

runner = CliRunner()


def exit_2(args: list[str], *expected: str) -> str:
    """``args`` exit 2 with one ``error:`` line on stderr holding every ``expected`` text."""
    result = runner.invoke(app, args)
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for text in expected:
        assert text in lines[0], (text, lines[0])
    return lines[0]


def with_source(**changes) -> dict:
    return {**TINY, "sources": [{**TINY["sources"][0], **changes}]}


def with_device(**changes) -> dict:
    return {**TINY, "devices": [{**TINY["devices"][0], **changes}]}


def with_window(**changes) -> dict:
    return {**TINY, "window": {**TINY["window"], **changes}}


DATASET_DEFECTS = [
    (with_source(subjects="five"), "sources[0].subjects must be an integer, got str 'five'"),
    (with_source(windows=1.5), "sources[0].windows must be an integer, got float 1.5"),
    (with_source(subjects=True), "sources[0].subjects must be an integer, got bool True"),
    (with_window(seconds="1"), "window.seconds must be a number, got str '1'"),
    (with_device(name=5), "devices[0].name must be a string, got int 5"),
    (with_source(activities=5), "sources[0].activities must be an array, got int 5"),
    (with_device(vr="yes"), "devices[0].vr must be a boolean (true or false), got str 'yes'"),
    (with_window(fps=1e300), "window.fps must be >= 1 and <= 1000, got 1e+300"),
    (with_window(seconds=float("inf")), "window.seconds must be a finite number, got float inf"),
    (with_window(seconds=float("nan")), "window.seconds must be a finite number"),
    (with_window(seconds=1e300), "window.seconds x window.fps = 1e+300 s x 30 fps", "memory"),
    (with_source(subjects=1_000_000_000), "2e+09 samples", "memory"),
    (with_source(windows=10**30), "sources.subjects x activities x windows", "PiB"),
    (with_device(image_scale=float("-inf")), "devices[0].image_scale must be a finite number"),
    ({**TINY, "splits": {"train": "all"}}, "splits.train must be a number"),
    ({**TINY, "colour": 1}, "unknown key 'colour' in [top level]; allowed: devices, name"),
]


@pytest.mark.parametrize("config, expected", [(c, e) for c, *e in DATASET_DEFECTS])
def test_a_hostile_dataset_config_exits_2_before_writing(tmp_path, config, expected):
    path = tmp_path / "c.toml"
    path.write_text(tomli_w.dumps(config))
    out = tmp_path / "out"
    start = time.perf_counter()
    exit_2(["dataset", "generate", str(path), "--out", str(out)], str(path), *expected)
    assert time.perf_counter() - start < 10.0  # refused at once, not after planning
    assert not out.exists()  # no dataset.json, so the corrected config is still accepted


def test_the_memory_limit_is_overridable_and_named(tmp_path, monkeypatch):
    """The shipped tiny config fits any machine; under a 1 MiB limit it is refused with the
    estimate and the variable that lifts the limit."""
    path = tmp_path / "c.toml"
    path.write_text(tomli_w.dumps(TINY))
    monkeypatch.setenv("AVATARSIM_MEMORY_LIMIT", "1M")
    line = exit_2(["dataset", "generate", str(path), "--out", str(tmp_path / "o")], "1 MiB")
    assert "AVATARSIM_MEMORY_LIMIT" in line and "needs about" in line
    assert not (tmp_path / "o").exists()


@pytest.fixture
def clip(tmp_path) -> Path:
    return save_motion(generate("walk", duration_s=0.5, fps=30.0), tmp_path / "walk.npz")


@pytest.mark.parametrize(
    "content, expected",
    [
        (bytes(range(256)) * 4, "not valid TOML"),
        (b"checks = 5\n", "checks must be a table, got int 5"),
        (b"[checks]\nfriction = true\n", "checks.friction must be a number, got bool True"),
        (b"penetration_cm_p95 = nan\n", "penetration_cm_p95 must be a finite number"),
        (b"penetration_cm_p95 = -1\n", "penetration_cm_p95 must be >= 0, got -1"),
        (b"contact_height = 0.05\n", "unknown key 'contact_height' in [top level]"),
    ],
)
def test_a_hostile_check_config_exits_2_before_writing(tmp_path, clip, content, expected):
    config = tmp_path / "c.toml"
    config.write_bytes(content)
    out = tmp_path / "out"
    exit_2(["check", str(clip), "--config", str(config), "--out", str(out)], str(config), expected)
    assert not out.exists()


@pytest.mark.parametrize(
    "toml, expected",
    [
        ("[motion]\nduration_s = inf\n", "motion.duration_s must be a finite number"),
        ("[motion]\nfps = 1e300\n", "motion.fps must be >= 1 and <= 1000"),
        ('[devices]\nvr = "yes"\n', "devices.vr must be a boolean"),
        ("[synthesis]\ndatabase_subjects = 1.5\n[devices]\n", "database_subjects must be an"),
        ("[physics]\nfriction = 1e999\n", "physics.friction must be a finite number"),
    ],
)
def test_a_hostile_scenario_exits_2_before_writing(tmp_path, toml, expected):
    scenario = tmp_path / "s.toml"
    scenario.write_text(toml)
    out = tmp_path / "out"
    exit_2(["run", str(scenario), "--out", str(out)], expected)
    assert not out.exists()


def test_a_long_scenario_is_refused_with_its_memory_estimate(tmp_path, monkeypatch):
    """600 s at 1000 Hz passes each field's bound; the frames together are refused, with the
    estimate, under a 1 GiB limit (600k frames need far more)."""
    scenario = tmp_path / "s.toml"
    scenario.write_text("[motion]\nduration_s = 600.0\nfps = 1000.0\n")
    monkeypatch.setenv("AVATARSIM_MEMORY_LIMIT", "1G")
    exit_2(["run", str(scenario), "--out", str(tmp_path / "o")], "600000 frames", "memory")
    assert not (tmp_path / "o").exists()

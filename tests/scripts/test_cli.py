"""CLI contract: exit codes and one-line reasons for bad input."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from scripts.cli import app

runner = CliRunner()


@pytest.mark.parametrize("command", ["info", "convert", "run", "demo", "bench"])
def test_every_command_has_help(command):
    result = runner.invoke(app, [command, "--help"])
    assert result.exit_code == 0
    assert "--seed" in result.output and "--json" in result.output


def test_missing_motion_file_exits_2(tmp_path):
    result = runner.invoke(app, ["info", str(tmp_path / "none.bvh")])
    assert result.exit_code == 2
    assert "no such file" in result.stderr


def test_unknown_format_exits_2(tmp_path):
    f = tmp_path / "walk.fbx"
    f.write_text("x")
    result = runner.invoke(app, ["info", str(f)])
    assert result.exit_code == 2 and "unknown motion format" in result.stderr


def test_invalid_scenario_exits_2_and_writes_nothing(tmp_path):
    sc = tmp_path / "s.toml"
    sc.write_text('[motion]\nactivty = "walk"\n')
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(sc), "--out", str(out)])
    assert result.exit_code == 2 and "activty" in result.stderr
    assert not out.exists()


def test_threshold_on_unknown_metric_exits_2(tmp_path):
    sc = tmp_path / "s.toml"
    sc.write_text("[thresholds]\nhappiness = 1.0\n")
    result = runner.invoke(app, ["run", str(sc), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "unknown metric" in result.stderr


def test_unknown_benchmark_exits_2():
    result = runner.invoke(app, ["bench", "nope"])
    assert result.exit_code == 2 and "unknown benchmark" in result.stderr

"""CLI contract: exit codes and one-line reasons for bad input."""

from __future__ import annotations

import pytest
import typer.main
from typer.testing import CliRunner

from avatarsim.scripts.cli import app

runner = CliRunner()


def _command_paths(command, path=()):
    """Every leaf command of the click tree typer builds, as its argv prefix."""
    children = getattr(command, "commands", None)
    if children is None:
        yield path
        return
    for name, child in sorted(children.items()):
        yield from _command_paths(child, (*path, name))


COMMANDS = list(_command_paths(typer.main.get_command(app)))


def test_the_registered_commands_are_enumerated():
    """The list below is read from the app, so a new command is covered without editing it;
    the 9 of the CLI contract that exist today must all be there."""
    names = {" ".join(c) for c in COMMANDS}
    assert {
        "info",
        "convert",
        "demo",
        "run",
        "check",
        "eval protocol",
        "render fisheye",
        "bench",
        "control",
    } <= names


@pytest.mark.parametrize("command", COMMANDS, ids=" ".join)
def test_every_command_has_help(command):
    result = runner.invoke(app, [*command, "--help"])
    assert result.exit_code == 0, result.output
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


def test_npz_takes_no_unit_and_directories_are_named(tmp_path):
    from avatarsim.avatar_models.formats import save_motion
    from avatarsim.avatar_models.generator import generate

    npz = save_motion(generate("wave", duration_s=0.2), tmp_path / "w.npz")
    result = runner.invoke(app, ["info", str(npz), "--unit", "cm"])
    assert result.exit_code == 2 and "NPZ files are always metres" in result.stderr
    result = runner.invoke(app, ["info", str(tmp_path)])
    assert result.exit_code == 2 and "is a directory" in result.stderr


def test_convert_to_an_unwritable_place_exits_2(tmp_path):
    from avatarsim.avatar_models.formats import save_motion
    from avatarsim.avatar_models.generator import generate

    npz = save_motion(generate("wave", duration_s=0.2), tmp_path / "w.npz")
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = runner.invoke(app, ["convert", str(npz), str(blocker / "sub" / "out.bvh")])
    assert result.exit_code == 2 and "is a file, not a folder" in result.stderr


def test_threshold_on_a_metric_the_scenario_does_not_produce_exits_2(tmp_path):
    sc = tmp_path / "s.toml"
    sc.write_text("[thresholds]\ncoolmoves_err_cm_full = 9.0\n")  # no [synthesis] table
    out = tmp_path / "o"
    result = runner.invoke(app, ["run", str(sc), "--out", str(out)])
    assert result.exit_code == 2 and "does not produce" in result.stderr
    assert not out.exists() and not list(tmp_path.glob(".o.partial-*"))


def test_a_bug_exits_3_not_1(monkeypatch, tmp_path):
    import avatarsim.avatar_models.formats as formats

    def broken(*args, **kwargs):
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(formats, "load_motion", broken)
    f = tmp_path / "a.bvh"
    f.write_text("HIERARCHY\n")
    result = runner.invoke(app, ["info", str(f)])
    assert result.exit_code == 3 and "internal error" in result.stderr


def test_builtin_motions_work_wherever_a_motion_file_does(tmp_path):
    info = runner.invoke(app, ["info", "builtin:squat", "--json", str(tmp_path / "i.json")])
    assert info.exit_code == 0, info.output
    out = tmp_path / "kick.bvh"
    assert runner.invoke(app, ["convert", "builtin:kick", str(out), "--fps", "30"]).exit_code == 0
    # The written BVH reads back as the generated motion's frame count at 30 fps (4 s).
    back = runner.invoke(app, ["info", str(out), "--json", str(tmp_path / "k.json")])
    assert back.exit_code == 0
    import json

    assert json.loads((tmp_path / "k.json").read_text())["frames"] == 121

"""``avatarsim eval``: contract JSON and plots; exit 2 with a reason for bad input."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from avatarsim.scripts.cli import app

runner = CliRunner()
SMALL = ["--subjects", "2", "--takes", "1", "--duration", "1.5", "--no-ablation"]


def test_eval_builtin_writes_contract_json_and_plots(tmp_path):
    out, js = tmp_path / "out", tmp_path / "r.json"
    result = runner.invoke(
        app,
        ["eval", "protocol", "coolmoves", "--library", "builtin", "--classes", "box", *SMALL,
         "--heading", "30", "--out", str(out), "--json", str(js)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    payload = json.loads(js.read_text())
    assert payload["heading_deg"] == 30.0 and "turned up to 30 deg" in result.output
    for summary in (payload["overall"], payload["per_activity"]["box"]):
        assert {"err_cm", "baseline_err_cm", "hand_corr", "frames_per_s"} <= set(summary)
        assert set(summary["err_cm"]) == {"hands", "upper", "lower", "full"}
    assert {p.name for p in out.iterdir()} >= {
        "eval.json",
        "errors_by_group.png",
        "errors_by_activity.png",
    }


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["eval", "protocol", "magic"], "unknown method"),
        (["eval", "protocol", "coolmoves", "--protocol", "cross-galaxy"], "unknown protocol"),
        (["eval", "movebox-study", "--protocol", "nonsense"], "No such option: --protocol"),
        (["eval", "protocol", "coolmoves", "--library", "/no/such/folder"], "not"),
        (["eval", "leaderboard", "--methods", "ik,magic"], "--methods"),
        (["eval", "protocol", "coolmoves", "--methods", "ik"], "No such option: --methods"),
        (["eval", "protocol", "coolmoves", "--solver", "x"], "No such option: --solver"),
        (["eval", "avatargo-study", "--audio", "x"], "No such option: --audio"),
        (["eval", "movebox-study", "--model", "x"], "No such option: --model"),
        (["eval", "controllerpose", "--model", "/no/run", "--data", "/no/ds"], "does not exist"),
        (["eval", "leaderboard", "--workers", "0"], "--workers"),
    ],
)
def test_bad_input_exits_2_with_a_reason(args, reason):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert reason in result.output


def test_folder_without_clips_exits_2(tmp_path):
    result = runner.invoke(app, ["eval", "protocol", "coolmoves", "--library", str(tmp_path)])
    assert result.exit_code == 2 and "no motion clips" in result.output


@pytest.mark.mocap
def test_bandai_cross_subject_says_why_it_is_impossible(mocap_dir):
    folder = mocap_dir / "bandai" / "dataset-2"
    result = runner.invoke(
        app, ["eval", "protocol", "coolmoves", "--library", str(folder), "--classes", "normal",
              "--max-per-class", "2", "--protocol", "cross-subject"],
    )  # fmt: skip
    assert result.exit_code == 2 and "subject labels" in result.output


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("coolmoves", "protocol coolmoves"),
        ("avatargo", "avatargo-study"),
        ("movebox", "movebox-study"),
    ],
)
def test_old_spellings_run_todays_command_with_a_deprecation_line(old, new):
    result = runner.invoke(app, ["eval", old, "--help"])
    assert result.exit_code == 0, result.output
    assert f"use eval {new}" in result.stderr
    assert f"eval {new.split()[0]} [OPTIONS]" in result.stdout  # the help of today's command

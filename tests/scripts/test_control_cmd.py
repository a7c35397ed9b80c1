"""``avatarsim control``: outputs and summary, exit 1 when the humanoid falls, exit 2 for bad
input, and nothing written on failure."""

from __future__ import annotations

import json

import mujoco
import numpy as np
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import save_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.cli import app

runner = CliRunner()


def test_control_searches_writes_outputs_and_exports(tmp_path):
    out, export, js = tmp_path / "out", tmp_path / "viewer", tmp_path / "r.json"
    args = ["control", "builtin:walk", "--seconds", "1", "--out", str(out), "--json", str(js)]
    result = runner.invoke(app, [*args, "--export", str(export)])
    assert result.exit_code == 0, result.output
    summary = json.loads(js.read_text())
    assert summary["mode"] == "search" and summary["fell"] is False
    assert summary["simulated_s"] >= 8 * 1.0  # every kept state is sampled 8 times
    assert json.loads((out / "control.json").read_text()) == summary
    written = {p.name for p in out.iterdir()}
    assert written == {"control.csv", "control.json", "control.png", ".avatarsim-output.json"}
    rows = np.genfromtxt(out / "control.csv", delimiter=",", names=True)
    assert len(rows) == 91 and rows["fallen"].max() == 0  # 1 s at the generator's 90 fps
    assert abs(rows["body17_err_cm"].mean() - summary["body17_err_cm_mean"]) < 1e-6
    model = mujoco.MjModel.from_xml_path(str(export / "replay.xml"))
    assert model.nkey == 91


def test_a_fall_exits_1(tmp_path):
    """A reference walking 3 m above the floor: the humanoid starts there and drops to the
    floor, its head far below the reference's: a fall."""
    motion = generate("walk", duration_s=1.5, fps=30.0)
    airborne = motion.replace(root_pos=motion.root_pos * [1.0, 1.0, 0.0] + [0.0, 0.0, 3.0])
    path = save_motion(airborne, tmp_path / "air.npz")
    result = runner.invoke(app, ["control", str(path), "--plain", "--out", str(tmp_path / "o")])
    assert result.exit_code == 1, result.output
    assert "fell" in result.output


def test_bad_input_exits_2_and_writes_nothing(tmp_path):
    path = save_motion(generate("walk", duration_s=1.0, fps=30.0), tmp_path / "w.npz")
    out = tmp_path / "o"
    for args in (["--seconds", "-1"], ["--samples", "0"]):
        result = runner.invoke(app, ["control", str(path), "--out", str(out), *args])
        assert result.exit_code == 2, result.output
    result = runner.invoke(app, ["control", str(tmp_path / "missing.bvh"), "--out", str(out)])
    assert result.exit_code == 2
    assert not out.exists()


def test_a_search_that_gives_up_before_the_end_exits_1_with_the_reason(tmp_path, monkeypatch):
    """The search may give up (every sample falls within its look-ahead) before the requested
    time without the body on the floor yet: that is no success, so it must not
    report "tracked 0.63 s, fell never" and exit 0."""
    import dataclasses

    import avatarsim.sim.control.search as control_search

    real = control_search.search

    def gives_up(model, qpos_ref, fps, **kwargs):
        searched = real(model, qpos_ref[: qpos_ref.shape[0] // 3], fps, **kwargs)
        return dataclasses.replace(searched, completed=False)

    monkeypatch.setattr(control_search, "search", gives_up)
    out, js = tmp_path / "o", tmp_path / "r.json"
    args = ["control", "builtin:walk", "--seconds", "0.6", "--samples", "2", "--beam", "1"]
    result = runner.invoke(app, [*args, "--out", str(out), "--json", str(js)])
    assert result.exit_code == 1, result.output
    assert "search exhausted" in result.output and "of 0.6" in result.output
    summary = json.loads(js.read_text())
    assert summary["completed"] is False and summary["failure"] == "search exhausted"
    assert summary["fell"] is False and summary["duration_s"] < summary["requested_s"]
    assert json.loads((out / "control.json").read_text())["failure"] == "search exhausted"


def test_a_completed_control_run_reports_no_failure(tmp_path):
    motion = generate("walk", duration_s=0.3, fps=30.0)
    path = save_motion(motion, tmp_path / "w.npz")
    js = tmp_path / "r.json"
    args = ["control", str(path), "--plain", "--out", str(tmp_path / "o"), "--json", str(js)]
    result = runner.invoke(app, args)
    summary = json.loads(js.read_text())
    assert result.exit_code == (0 if summary["completed"] else 1), result.output
    assert summary["failure"] in (None, "fell") and summary["requested_s"] == 10 / 30

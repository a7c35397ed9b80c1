"""``avatarsim check``: outputs, exit 0/1 from thresholds, exit 2 with a reason for bad input."""

from __future__ import annotations

import json

import mujoco
import numpy as np
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import save_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.cli import app
from avatarsim.sim.corrupt import float_body
from avatarsim.sim.plausibility import CONTRACT_KEYS

runner = CliRunner()


def test_check_writes_outputs_and_exports_for_the_viewer(tmp_path):
    path = save_motion(generate("squat", duration_s=1.0), tmp_path / "squat.npz")
    out, export, js = tmp_path / "out", tmp_path / "viewer", tmp_path / "r.json"
    result = runner.invoke(
        app, ["check", str(path), "--out", str(out), "--export", str(export), "--json", str(js)]
    )
    assert result.exit_code == 0, result.output
    payload = json.loads(js.read_text())
    assert set(CONTRACT_KEYS) <= set(payload) and payload["passed"] is True
    assert {p.name for p in out.iterdir()} == {"check.csv", "check.json", "check.png"}
    header = (out / "check.csv").read_text().splitlines()[0].split(",")
    assert "penetration_cm" in header and "residual_force_bw" in header
    model = mujoco.MjModel.from_xml_path(str(export / "replay.xml"))
    qpos = np.load(export / "qpos.npy")
    assert model.nkey == len(qpos) and np.allclose(model.key_qpos[-1], qpos[-1], atol=1e-6)


def test_failing_threshold_exits_1(tmp_path):
    path = save_motion(float_body(generate("squat", duration_s=1.0)), tmp_path / "f.npz")
    result = runner.invoke(app, ["check", str(path), "--out", str(tmp_path / "o")])
    assert result.exit_code == 1 and "float_cm_p95" in result.output


def test_config_file_changes_thresholds(tmp_path):
    path = save_motion(generate("squat", duration_s=1.0), tmp_path / "s.npz")
    cfg = tmp_path / "c.toml"
    cfg.write_text("jitter_m_s3_median = 0.0\n")
    result = runner.invoke(app, ["check", str(path), "--config", str(cfg), "--out", str(tmp_path)])
    assert result.exit_code == 1


def test_bad_input_exits_2_with_a_reason(tmp_path):
    nan = tmp_path / "nan.bvh"
    nan.write_text(
        "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
        "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\nnan 0 0\n"
    )
    empty = tmp_path / "empty.bvh"
    empty.write_text(nan.read_text().replace("Frames: 1", "Frames: 0").replace("nan 0 0\n", ""))
    for path in (nan, empty, tmp_path / "missing.bvh"):
        result = runner.invoke(app, ["check", str(path), "--out", str(tmp_path / "o")])
        assert result.exit_code == 2, (path, result.output)
        assert "error:" in result.stderr
    cfg = tmp_path / "bad.toml"
    cfg.write_text("nonsense = 1\n")
    path = save_motion(generate("squat", duration_s=0.2), tmp_path / "s.npz")
    result = runner.invoke(app, ["check", str(path), "--config", str(cfg)])
    assert result.exit_code == 2 and "unknown key 'nonsense'" in result.stderr


def test_unknown_rig_exits_2(tmp_path):
    bvh = tmp_path / "stick.bvh"
    bvh.write_text(
        "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
        "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 2\nFrame Time: 0.01\n0 0 0\n0 0 0\n"
    )
    result = runner.invoke(app, ["check", str(bvh), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "rig" in result.stderr


def test_corrupt_makes_the_check_for_that_defect_fail(tmp_path):
    path = save_motion(generate("walk", duration_s=2.0, seed=1), tmp_path / "w.npz")
    js = tmp_path / "c.json"
    args = ["check", str(path), "--out", str(tmp_path / "o"), "--json", str(js)]
    result = runner.invoke(app, [*args, "--corrupt", "floating"])
    assert result.exit_code == 1
    floating = [c for c in json.loads(js.read_text())["checks"] if c["check"] == "floating"]
    assert floating and not all(c["passed"] for c in floating)
    result = runner.invoke(app, [*args, "--corrupt", "melting"])
    assert result.exit_code == 2 and "defects are" in result.stderr

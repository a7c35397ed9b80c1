"""``avatarsim train controllerpose`` and ``avatarsim eval controllerpose``: what they write,
resume, and the bad inputs that exit 2 before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from typer.testing import CliRunner

from avatarsim.scripts.cli import app
from avatarsim.synthesis.controllerpose.checkpoint import load
from tests.scripts.controllerpose.conftest import tiny_dataset

runner = CliRunner()


def test_train_writes_checkpoint_curves_and_summary(cp_run):
    summary = json.loads((cp_run / "train.json").read_text())
    assert summary["epochs"] == 2 and summary["examples"]["train"] > 0
    assert (cp_run / "loss.png").read_bytes()[:4] == b"\x89PNG"
    checkpoint = load(cp_run)
    assert checkpoint.manifest_sha256 == summary["manifest_sha256"]
    assert checkpoint.train["seed"] == 0


def test_train_resumes_a_finished_run_without_retraining(cp_run, cp_dataset):
    before = load(cp_run).best_weights
    result = runner.invoke(
        app,
        ["train", "controllerpose", "--data", str(cp_dataset), "--out", str(cp_run),
         "--max-epochs", "2", "--width", "32", "--blocks", "1"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert json.loads((cp_run / "train.json").read_text())["resumed"]
    after = load(cp_run).best_weights
    assert all(torch.equal(before[k], after[k]) for k in before)


def test_eval_reports_model_baseline_and_ablation(cp_run, cp_dataset, tmp_path):
    result = runner.invoke(
        app,
        ["eval", "controllerpose", "--model", str(cp_run), "--data", str(cp_dataset),
         "--no-vr-model", str(cp_run), "--out", str(tmp_path / "eval")],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "eval" / "eval.json").read_text())
    methods = {"controllerpose", "nearest-neighbour", "controllerpose-no-vr", "coolmoves"}
    assert set(report["results"]) == methods
    for name in methods:  # the same frames, §5.3-normalised: the pelvis is the origin
        res = report["results"][name]
        assert res["frames"] == report["results"]["controllerpose"]["frames"]
        assert np.isfinite(res["mean_cm"]) and res["per_joint_cm"]["pelvis"] < 1e-6
    # The paper's numbers come with what its protocol does otherwise (§5.2: a Kinect V2 as
    # ground truth; §4.3: OpenPose on real images; §5: 8 participants), in the JSON and printed.
    differs = report["paper_differs"]
    assert set(differs) == {"ground_truth", "keypoints", "subjects"}
    assert "Kinect V2" in differs["ground_truth"] and "OpenPose" in differs["keypoints"]
    text = " ".join(result.output.split())
    assert "6.98 cm" in text and "on another protocol" in text
    assert all(" ".join(d.split()) in text for d in differs.values())


@pytest.mark.mocap
def test_eval_labels_real_clips_as_real_motion_through_simulated_sensors(
    cp_run, cp_dataset, mocap_dir, tmp_path
):
    """A real clip (one Bandai walk) goes through the simulated VR devices and fisheye
    cameras: its rows and JSON say so, not "real" alone."""
    clips = tmp_path / "clips"
    clips.mkdir()
    (clips / "walk.bvh").symlink_to(
        mocap_dir / "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"
    )
    result = runner.invoke(
        app,
        ["eval", "controllerpose", "--model", str(cp_run), "--data", str(cp_dataset),
         "--mocap", str(clips), "--out", str(tmp_path / "eval")],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "eval" / "eval.json").read_text())
    assert report["real_mocap_is"] == "real motion, simulated sensors"
    assert np.isfinite(report["real_mocap"]["controllerpose"]["mean_cm"])
    lines = [line.split("│") for line in result.output.splitlines() if line.startswith("│")]
    tests = " ".join(" ".join(cells[1] for cells in lines).split())  # the wrapped first column
    assert tests.count("real motion, simulated sensors") == len(report["real_mocap"])


def test_a_dataset_without_keypoints_exits_2(tmp_path):
    no_fisheye = tiny_dataset(tmp_path, [{"name": "vr", "fisheye": False, "physics": False}])
    result = runner.invoke(
        app, ["train", "controllerpose", "--data", str(no_fisheye), "--out", str(tmp_path / "r")]
    )
    assert result.exit_code == 2 and "fisheye" in result.output
    assert not (tmp_path / "r").exists()


def test_a_checkpoint_of_another_feature_layout_exits_2(cp_run, cp_dataset, tmp_path):
    payload = torch.load(cp_run / "checkpoint.pt", weights_only=True)
    payload["layout"] = {**payload["layout"], "skeleton_slots": 2}
    (tmp_path / "old").mkdir()
    torch.save(payload, tmp_path / "old" / "checkpoint.pt")
    result = runner.invoke(
        app,
        ["eval", "controllerpose", "--model", str(tmp_path / "old"), "--data", str(cp_dataset),
         "--out", str(tmp_path / "eval")],
    )  # fmt: skip
    assert result.exit_code == 2 and "feature layout" in result.output


def test_nan_in_the_features_exits_2(cp_dataset, tmp_path, monkeypatch):
    import avatarsim.scripts.controllerpose.training as training

    real = training.load_examples

    def with_nan(root, split, stride):
        examples = real(root, split, stride)
        examples.features.skeletons[0, 0, 5] = np.nan
        return examples

    monkeypatch.setattr(training, "load_examples", with_nan)
    result = runner.invoke(
        app, ["train", "controllerpose", "--data", str(cp_dataset), "--out", str(tmp_path / "r")]
    )
    assert result.exit_code == 2 and "non-finite" in result.output
    assert not (tmp_path / "r" / "checkpoint.pt").exists()


def test_an_occupied_out_that_holds_no_run_exits_2(cp_dataset, tmp_path):
    # Regression: training wrote its checkpoint among unrelated files.
    occupied = tmp_path / "occupied"
    occupied.mkdir()
    (occupied / "notes.txt").write_text("mine")
    args = ["train", "controllerpose", "--data", str(cp_dataset), "--max-epochs", "1"]
    result = runner.invoke(app, [*args, "--out", str(occupied)])
    assert result.exit_code == 2 and "not empty" in result.output
    assert sorted(p.name for p in occupied.iterdir()) == ["notes.txt"]
    result = runner.invoke(app, [*args, "--out", str(occupied / "notes.txt")])
    assert result.exit_code == 2 and "is a file" in result.output


def test_the_shipped_scenario_without_a_model_exits_2_before_any_stage(tmp_path, monkeypatch):
    from pathlib import Path

    from avatarsim.synthesis.controllerpose.synthesizer import MODEL_ENV

    scenario = Path(__file__).resolve().parents[3] / "scripts/scenarios/methods/controllerpose.toml"
    monkeypatch.setenv(MODEL_ENV, str(tmp_path / "no-model"))
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "run")])
    assert result.exit_code == 2
    assert "no trained model" in result.output and "train controllerpose" in result.output
    assert not (tmp_path / "run").exists()

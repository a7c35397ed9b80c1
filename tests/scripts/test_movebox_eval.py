"""``avatarsim eval movebox-study``: the numbers, the story and a recorded take on built-in motion,
a real clip of each mocap source, and exit 2 for bad input before any work."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from typer.testing import CliRunner

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect import Kinect, TrackingState
from avatarsim.scripts.cli import app
from avatarsim.scripts.movebox_eval import mean_cm, shown_tracked, summarise
from tests.synthesis.movebox.conftest import AUDIO_DIR

runner = CliRunner()
SOURCES = ("cmu", "dataset-1", "dataset-2")


def write_skeleton_recording(stream, folder: Path) -> Path:
    """A Kinect recording folder holding only what MoveBox reads: skeleton frames and the
    record (the depth frames are not needed)."""
    (folder / "skeleton").mkdir(parents=True)
    for t in range(stream.n_samples):
        (folder / "skeleton" / f"{t:06d}.json").write_text(stream.to_json(t))
    record = {
        "device": stream.meta["device"],
        "fps": 30.0,
        "camera_to_world": stream.sensor_pose.tolist(),
    }
    (folder / "recording.json").write_text(json.dumps(record))
    return folder


@pytest.fixture(scope="module")
def recorded_stream():
    return Kinect().sample(generate("wave", duration_s=1.0, fps=30.0, seed=2), seed=2).skeleton


def test_builtin_numbers_story_and_recorded_take(tmp_path, recorded_stream):
    take = write_skeleton_recording(recorded_stream, tmp_path / "take")
    out, js = tmp_path / "out", tmp_path / "r.json"
    args = ["eval", "movebox-study", "--quick", "--classes", "walk", "--duration", "1.5",
            "--kinect", str(take), "--out", str(out), "--json", str(js)]  # fmt: skip
    if (AUDIO_DIR / "hello.wav").is_file():
        args += ["--audio", str(AUDIO_DIR / "hello.wav")]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    payload = json.loads(js.read_text())
    # Every table names its roll: the retargeting's hinge roll, which MoveBox's paper does not
    # use (§IV-B1: the avatar's rest roll for Kinect V2, the sensor's own for Azure Kinect),
    # and the method's paper roll per sensor.
    assert payload["roll"] == {
        "retargeting": "hinge",
        "method": {"kinect-v2": "rest", "azure-kinect": "sensor"},
    }
    text = " ".join(result.output.split())
    assert "movebox retargeting (hinge roll, beyond the paper)" in text
    assert "movebox method (the paper's roll per sensor)" in text
    assert "builtin │ kinect-v2 │ rest" in text and "builtin │ azure-kinect │ sensor" in text
    # Which skeleton the Kinect reported is said where the numbers are: by default the tracker.
    assert payload["skeleton"] == "tracker"
    assert "Kinect skeleton: tracker" in text
    for sensor in ("kinect-v2", "azure-kinect"):
        row = payload["summary"]["builtin"][sensor]
        assert row["retarget_err_cm"]["noise_free"] < 1.0
        assert row["roll_err_deg"]["hinge"] <= 10.0
        assert row["jitter_m_s3"]["smoothed"] < row["jitter_m_s3"]["unsmoothed"]
        assert row["loop_seam"]["trimmed"] <= row["loop_seam"]["naive"]
        assert "penetration_cm_p95" in row["method"]["physics"]
    model = mujoco.MjModel.from_xml_path(payload["story"]["scene"])
    assert model.nkey > 1 and Path(payload["story"]["video"]).stat().st_size > 0
    assert {Path(f).suffix for f in payload["take"]["files"]} == {".npz", ".bvh"}


def test_shown_tracked_is_the_latest_kinect_frame_at_or_before_each_tick(recorded_stream):
    rig = load_rig(recorded_stream.rig)
    states = np.full_like(recorded_stream.states, TrackingState.TRACKED)
    states[1, rig.body17_indices()[5]] = TrackingState.INFERRED  # frame 1: a wrist guessed
    stream = replace(recorded_stream, states=states)
    frame = 1.0 / 30.0
    ticks = np.array([-0.01, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5]) * frame + stream.timestamps[0]
    shown = shown_tracked(stream, ticks)
    assert shown.tolist() == [False, True, True, False, False, True, True]


def test_a_take_never_tracked_whole_has_nan_tracked_errors_left_out_of_the_means():
    err = np.full((4, 17), 0.02)
    assert mean_cm(err, np.ones(4, bool)) == pytest.approx(2.0)
    assert np.isnan(mean_cm(err, np.zeros(4, bool)))
    rows = {"a": {"s": {"e": 2.0}}, "b": {"s": {"e": float("nan")}}, "c": {"s": {"e": 4.0}}}
    assert summarise(rows, ["s"])["real"]["s"]["e"] == pytest.approx(3.0)


@pytest.mark.mocap
def test_real_clip_of_each_source(tmp_path, mocap_dir):
    out, js = tmp_path / "out", tmp_path / "r.json"
    result = runner.invoke(
        app,
        ["eval", "movebox-study", "--library", str(mocap_dir), "--quick", "--duration", "1.0",
         "--out", str(out), "--json", str(js)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    payload = json.loads(js.read_text())
    labels = list(payload["takes"])
    assert all(any(source in label for label in labels) for source in SOURCES), labels
    for row in payload["takes"].values():
        for sensor in ("kinect-v2", "azure-kinect"):
            assert row[sensor]["method"]["err_cm"]["full"] < 30.0
            assert 0.0 <= row[sensor]["tracked_frames_frac"] <= 1.0
            assert set(row[sensor]["method"]["err_cm_tracked"]) == {
                "hands",
                "upper",
                "lower",
                "full",
            }


@pytest.mark.parametrize("case", ["audio", "empty", "never-tracked", "not-a-recording"])
def test_bad_input_exits_2_before_work(tmp_path, recorded_stream, case):
    args = ["eval", "movebox-study", "--out", str(tmp_path / "out")]
    if case == "audio":
        bad = tmp_path / "voice.mp3"
        bad.write_bytes(b"ID3\x03 an mp3, not a wav")
        args += ["--audio", str(bad)]
        reason = "unknown audio format"
    elif case == "empty":
        (tmp_path / "take" / "skeleton").mkdir(parents=True)
        args += ["--kinect", str(tmp_path / "take")]
        reason = "no Kinect skeleton frames"
    elif case == "never-tracked":
        blind = replace(recorded_stream, states=recorded_stream.states * 0)
        args += ["--kinect", str(write_skeleton_recording(blind, tmp_path / "take"))]
        reason = "NotTracked"
    else:
        (tmp_path / "take" / "skeleton").mkdir(parents=True)
        (tmp_path / "take" / "skeleton" / "000000.json").write_text("{not json")
        args += ["--kinect", str(tmp_path / "take")]
        reason = "not a Kinect recording"
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert reason in result.output
    assert not (tmp_path / "out").exists()

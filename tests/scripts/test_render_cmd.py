"""``avatarsim render DEVICE``: files a device would record, and exit 2 for bad input."""

from __future__ import annotations

import json

import imageio.v3 as iio
import numpy as np
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import save_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.kinect.placement import performer_distance
from avatarsim.scripts.cli import app

runner = CliRunner()


def test_kinect_render_writes_depth_in_millimetres(tmp_path):
    out = tmp_path / "kinect"
    result = runner.invoke(
        app,
        [
            "render",
            "kinect-v2",
            "builtin:wave",
            "--out",
            str(out),
            "--duration-s",
            "0.2",
            "--json",
            str(tmp_path / "r.json"),
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "r.json").read_text())
    assert summary["frames"] == 7 and summary["fps_rendered"] > 0  # 0.2 s at 30 Hz
    depth = iio.imread(sorted((out / "depth").glob("*.png"))[0])
    body_index = iio.imread(sorted((out / "body_index").glob("*.png"))[0])
    assert depth.dtype == np.uint16 and depth.shape == (424, 512)
    # The body is where the sensor was set up: the pelvis's depth from the recorded pose and
    # the same built-in motion, within 0.3 m (the body's own depth and the noise).
    pose = np.array(json.loads((out / "recording.json").read_text())["camera_to_world"])
    placed = performer_distance(pose, generate("wave", duration_s=0.2, seed=0)[:1])[0]
    assert 1.0 < placed < 4.0
    body = depth[(body_index == 0) & (depth > 0)]
    assert body.size > 1000
    assert abs(np.median(body) / 1e3 - placed) < 0.3


def test_the_skeleton_is_tracked_unless_the_oracle_is_asked_for_and_then_labelled(tmp_path):
    for skeleton, label in (("tracker", None), ("oracle-noise", "not a sensor")):
        out = tmp_path / skeleton
        args = ["render", "kinect-v2", "builtin:wave", "--out", str(out), "--duration-s", "0.1"]
        result = runner.invoke(app, [*args, "--kinect-skeleton", skeleton])
        assert result.exit_code == 0, result.output
        record = json.loads((out / "recording.json").read_text())
        frame = json.loads(sorted((out / "skeleton").glob("*.json"))[0].read_text())
        assert record["skeleton"] == skeleton
        for labelled in (record, frame):
            note = labelled.get("skeleton_note")
            assert (note is None) if label is None else note.startswith(label)


def test_sensor_pose_and_frame_range_options(tmp_path):
    out = tmp_path / "k"
    args = ["render", "azure-kinect", "builtin:walk", "--out", str(out)]
    result = runner.invoke(
        app,
        [
            *args,
            "--start",
            "0.5",
            "--end",
            "1.0",
            "--sensor-pos",
            "2.5,0,0.8",
            "--sensor-yaw",
            "180",
        ],
    )
    assert result.exit_code == 0, result.output
    record = json.loads((out / "recording.json").read_text())
    assert record["frames"] == 16 and record["sensor_placement"] == "given"  # 0.5 s at 30 Hz
    pose = np.array(record["camera_to_world"])
    np.testing.assert_allclose(pose[:3, 3], [2.5, 0.0, 0.8])
    np.testing.assert_allclose(pose[:3, 2], [-1.0, 0.0, 0.0], atol=1e-9)
    fish = runner.invoke(
        app,
        ["render", "fisheye", "builtin:walk", "--out", str(tmp_path / "f"), "--size", "64,48",
         "--end", "0.1", "--ring-offset", "0.03,0,0.05", "--grip-pitch", "-40"],
    )  # fmt: skip
    assert fish.exit_code == 0, fish.output


def test_options_of_another_device_exit_2_as_unknown(tmp_path):
    for device, extra in (
        ("kinect-v2", ["--fov", "150,120"]),
        ("azure-kinect", ["--ring-offset", "0,0,0.1"]),
        ("fisheye", ["--sensor-pos", "2,0,1"]),
    ):
        result = runner.invoke(
            app, ["render", device, "builtin:walk", "--out", str(tmp_path), *extra]
        )
        assert result.exit_code == 2, (device, result.output)
        assert f"No such option: {extra[0]}" in result.output
    assert not any(tmp_path.iterdir())


def test_bad_ranges_and_placements_exit_2(tmp_path):
    cases = [
        ("kinect-v2", ["--sensor-yaw", "90"], "need --sensor-pos"),
        ("kinect-v2", ["--sensor-pos", "2,0"], "three numbers"),
        ("kinect-v2", ["--sensor-pos", "2,0,1", "--sensor-height", "1"], "not both"),
        (
            "kinect-v2",
            ["--sensor-pos", "2,0,1", "--sensor-look-at", "0,0,1", "--sensor-pitch", "3"],
            "not both",
        ),
        ("kinect-v2", ["--sensor-pos", "2,0,-1"], "below the floor"),
        ("fisheye", ["--end", "1", "--duration-s", "1"], "not both"),
        ("azure-kinect", ["--start", "1", "--end", "0.5"], "after --start"),
        ("fisheye", ["--end", "soon"], "seconds or 'end'"),
        ("fisheye", ["--ring-offset", "0.5,0,0"], "within"),
        ("kinect-v2", ["--kinect-skeleton", "truth"], "must be one of"),
    ]
    for device, extra, message in cases:
        args = ["render", device, "builtin:walk", "--out", str(tmp_path), *extra]
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (extra, result.output)
        assert message in result.stderr, (extra, result.stderr)


def test_the_old_spelling_renders_the_same_with_a_deprecation_line(tmp_path):
    """``render MOTION --device D`` runs ``render D MOTION``: the same files, byte for byte."""
    common = ["--duration-s", "0.1", "--size", "32,24", "--seed", "4"]
    old = runner.invoke(
        app,
        ["render", "builtin:wave", "--device", "fisheye", "--out", str(tmp_path / "old"), *common],
    )
    new = runner.invoke(
        app, ["render", "fisheye", "builtin:wave", "--out", str(tmp_path / "new"), *common]
    )
    assert old.exit_code == 0 and new.exit_code == 0, old.output + new.output
    assert "deprecated: render MOTION --device fisheye: use render fisheye MOTION" in old.stderr
    assert "deprecated" not in new.stderr
    files = sorted(p.relative_to(tmp_path / "new") for p in (tmp_path / "new").rglob("*.png"))
    assert files
    for name in files:
        assert (tmp_path / "old" / name).read_bytes() == (tmp_path / "new" / name).read_bytes()
    default = runner.invoke(app, ["render", "builtin:wave", "--out", str(tmp_path / "d"), *common])
    assert default.exit_code == 0 and "use render fisheye MOTION" in default.stderr


def test_frame_range_past_a_file_clip_exits_2(tmp_path):
    clip = save_motion(generate("walk", duration_s=1.0, seed=0), tmp_path / "walk.npz")
    render = ["render", "fisheye", str(clip), "--out", str(tmp_path / "o")]
    late = runner.invoke(app, [*render, "--start", "5"])
    assert late.exit_code == 2 and "past the clip's end" in late.stderr
    long = runner.invoke(app, [*render, "--end", "3"])
    assert long.exit_code == 2 and "--end end" in long.stderr


def test_unknown_device_and_activity_exit_2(tmp_path):
    bad = runner.invoke(
        app, ["render", "builtin:walk", "--device", "lidar", "--out", str(tmp_path)]
    )
    assert bad.exit_code == 2 and "No such command 'lidar'" in bad.output
    bad = runner.invoke(app, ["render", "fisheye", "builtin:fly", "--out", str(tmp_path)])
    assert bad.exit_code == 2 and "unknown built-in activity" in bad.stderr


def test_impossible_fisheye_intrinsics_exit_2(tmp_path):
    wide = runner.invoke(
        app, ["render", "fisheye", "builtin:walk", "--fov", "200,120", "--out", str(tmp_path)]
    )
    assert wide.exit_code == 2 and "FOV" in wide.stderr
    garbled = runner.invoke(
        app, ["render", "fisheye", "builtin:walk", "--size", "640", "--out", str(tmp_path)]
    )
    assert garbled.exit_code == 2 and "--size takes two numbers" in garbled.stderr
    assert not any(tmp_path.iterdir())  # nothing written for bad input

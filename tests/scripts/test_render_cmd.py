"""``avatarsim render``: files a device would record, and exit 2 for bad input."""

from __future__ import annotations

import json

import imageio.v3 as iio
import numpy as np
from typer.testing import CliRunner

from scripts.cli import app

runner = CliRunner()


def test_kinect_render_writes_depth_in_millimetres(tmp_path):
    out = tmp_path / "kinect"
    result = runner.invoke(
        app,
        [
            "render",
            "builtin:wave",
            "--device",
            "kinect-v2",
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
    assert depth.dtype == np.uint16 and depth.shape == (424, 512)
    body = depth[depth > 0]
    # The user stands about 2 m from the sensor (default pose): body and floor in range.
    assert 500 <= np.median(body) <= 4500


def test_unknown_device_and_activity_exit_2(tmp_path):
    bad = runner.invoke(
        app, ["render", "builtin:walk", "--device", "lidar", "--out", str(tmp_path)]
    )
    assert bad.exit_code == 2 and "unknown device" in bad.stderr
    bad = runner.invoke(app, ["render", "builtin:fly", "--out", str(tmp_path)])
    assert bad.exit_code == 2 and "unknown built-in activity" in bad.stderr


def test_impossible_fisheye_intrinsics_exit_2(tmp_path):
    wide = runner.invoke(
        app, ["render", "builtin:walk", "--fov", "200,120", "--out", str(tmp_path)]
    )
    assert wide.exit_code == 2 and "FOV" in wide.stderr
    garbled = runner.invoke(
        app, ["render", "builtin:walk", "--size", "640", "--out", str(tmp_path)]
    )
    assert garbled.exit_code == 2 and "--size takes two numbers" in garbled.stderr
    assert not any(tmp_path.iterdir())  # nothing written for bad input

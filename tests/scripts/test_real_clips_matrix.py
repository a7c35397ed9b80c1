"""Every command on a short slice of a real clip of each source, and on built-in motion.

The same matrix as ``../shared/tools/real-clips-matrix.sh`` (which runs the full clips): a
cell passes with exit 0, or 1 where a check honestly fails (a physics threshold, a fall);
never 2 (our input is valid) or 3 (a bug).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from avatarsim.avatar_models.formats import load_motion, save_motion
from avatarsim.scripts.cli import app

runner = CliRunner()

CLIPS = {
    "cmu": ("cmu/09_01.bvh", 0.05),  # a 1.24 s run; its frame 0 is a T-pose
    "bandai-1": ("bandai/dataset-1/data/dataset-1_walk_normal_001.bvh", 1.0),
    "bandai-2": ("bandai/dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh", 1.0),
}
"""Source -> clip and the second its slice starts at."""
SLICE_S = 1.1
"""Slice length: enough for every stage (a 0.5 s control run loops a gait cycle of >= 0.8 s)."""
COMMANDS = ("info", "convert", "check", "control", "fisheye", "kinect-v2", "azure-kinect", "run")

SCENARIO = """
name = "matrix-{source}"
seed = 0
[motion]
source = "{path}"
{builtin}duration_s = 1.0
fps = 90.0
[report]
picture_frames = 3
gif = false
[devices]
vr = true
noise = "realistic"
[synthesis]
methods = ["coolmoves", "ik"]
database_subjects = 2
database_duration_s = 4.0
[cameras]
fisheye = true
kinect = "kinect-v2"
[control]
seconds = 0.5
search = false
"""


@pytest.fixture(scope="module")
def sliced(mocap_dir, tmp_path_factory) -> dict[str, str]:
    """Source name -> the MOTION argument: a BVH slice of the real clip, or builtin:walk."""
    out = {"builtin": "builtin:walk"}
    folder = tmp_path_factory.mktemp("clips")
    for name, (rel, start_s) in CLIPS.items():
        motion = load_motion(mocap_dir / rel)
        a = int(round(start_s * motion.fps))
        sliced = motion[a : a + int(round(SLICE_S * motion.fps))]
        out[name] = str(save_motion(sliced, folder / f"{name}.bvh"))
    return out


def _invoke(command: str, motion: str, tmp: Path) -> tuple[int, str]:
    js = tmp / "result.json"
    if command == "info":
        args = ["info", motion, "--json", str(js)]
    elif command == "convert":
        args = ["convert", motion, str(tmp / "converted.npz"), "--fps", "60"]
    elif command == "check":
        args = ["check", motion, "--out", str(tmp / "out"), "--json", str(js)]
    elif command == "control":
        args = ["control", motion, "--seconds", "0.5", "--plain", "--out", str(tmp / "out")]
        args += ["--json", str(js)]
    elif command == "run":
        source, builtin = motion, ""
        if motion.startswith("builtin:"):
            source, builtin = "builtin", f'activity = "{motion.split(":")[1]}"\n'
        scenario = tmp / "scenario.toml"
        scenario.write_text(SCENARIO.format(source=tmp.name, path=source, builtin=builtin))
        args = ["run", str(scenario), "--out", str(tmp / "out"), "--json", str(js)]
    else:
        args = ["render", command, motion, "--duration-s", "0.3"]
        args += ["--out", str(tmp / "out"), "--json", str(js)]
    result = runner.invoke(app, args)
    return result.exit_code, result.output


@pytest.mark.mocap
@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("source", ["cmu", "bandai-1", "bandai-2", "builtin"])
def test_every_command_on_every_source(sliced, source, command, tmp_path):
    code, output = _invoke(command, sliced[source], tmp_path)
    assert code in (0, 1), f"{command} on {source}: exit {code}\n{output[-2000:]}"
    if command == "convert":
        assert (tmp_path / "converted.npz").is_file()
        assert load_motion(tmp_path / "converted.npz").fps == 60.0
        return
    payload = json.loads((tmp_path / "result.json").read_text())
    if command == "info":
        assert 1.0 < payload["height_m"] < 2.2, payload
    elif command == "check":
        assert payload["meta"]["retargeted"] == source.startswith("bandai")
    elif command == "control":
        assert payload["duration_s"] == pytest.approx(0.5, abs=0.05) or code == 1
    elif command == "run":
        assert payload["metrics"]["replay_error_mm_max"] < 1.0  # qpos replays the motion
        assert payload["body"]["retargeted"] == source.startswith("bandai")
        assert (tmp_path / "out" / "report.html").is_file()
    else:
        assert payload["frames"] > 0

"""Hostile input on the newer paths: absurd motion values, damaged WAV files, baselines of
the wrong types give exit 2 before any work; a user's file is never replaced by an output."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.io import wavfile
from typer.testing import CliRunner

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.formats import load_motion, save_motion
from avatarsim.avatar_models.generator import ACTIVITIES, generate
from avatarsim.avatar_models.motion_bounds import check_physical
from avatarsim.scripts.cli import app
from avatarsim.scripts.scenario import DEFAULT_SCENARIO

runner = CliRunner()


def _reason(result) -> str:
    return " ".join(result.output.split())


def _cmu_with(mocap_dir: Path, tmp_path: Path, frame: int, column: int, value: str) -> Path:
    """CMU 09_01 with frame line ``frame``'s value ``column`` set to ``value``."""
    lines = (mocap_dir / "cmu" / "09_01.bvh").read_text().split("\n")
    first = next(k for k, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    row = lines[first + frame].split()
    row[column] = value
    lines[first + frame] = " ".join(row)
    path = tmp_path / "bad.bvh"
    path.write_text("\n".join(lines))
    return path


@pytest.mark.mocap
def test_a_cmu_channel_of_1e300_is_exit_2_with_file_frame_and_channel(mocap_dir, tmp_path):
    bad = _cmu_with(mocap_dir, tmp_path, frame=5, column=0, value="1e300")  # Hips Xposition
    out = str(tmp_path / "o")
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'[motion]\nsource = "{bad}"\n')
    for args in (
        ["info", str(bad)],
        ["convert", str(bad), str(tmp_path / "c.npz")],
        ["check", str(bad), "--out", out],
        ["control", str(bad), "--out", out],
        ["render", "fisheye", str(bad), "--out", out],
        ["run", str(scenario), "--out", out],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
        assert f"{bad}: frame 5 (from 0), joint 'Hips' world" in _reason(result), args
    assert not (tmp_path / "o").exists() and not (tmp_path / "c.npz").exists()


@pytest.mark.mocap
def test_real_clips_and_builtin_motion_pass_the_bounds(mocap_dir):
    for clip in sorted((mocap_dir / "cmu").glob("*.bvh")):
        load_motion(clip)
    for activity in ACTIVITIES:
        check_physical(generate(activity, duration_s=2.0, seed=1), activity)


def test_builtin_motion_a_kilometre_away_or_teleporting_is_refused(tmp_path):
    walk = generate("walk", duration_s=1.0)
    far = walk.translated(np.array([2000.0, 0.0, 0.0]))
    with pytest.raises(MotionValueError, match="more than 1000 m"):
        load_motion(save_motion(far, tmp_path / "far.npz"))
    root = walk.root_pos.copy()
    root[10:] += [5.0, 0.0, 0.0]  # 5 m in one frame at 30 fps: 150 m/s
    with pytest.raises(MotionValueError, match=r"frame 10 \(from 0\).*m/s"):
        load_motion(save_motion(walk.replace(root_pos=root), tmp_path / "jump.npz"))


def _wav(tmp_path: Path, kind: str) -> Path:
    path = tmp_path / f"{kind}.wav"
    tone = (np.sin(np.arange(16000) * 0.3) * 8000).astype(np.int16)
    if kind == "1hz":
        wavfile.write(path, 1, tone)
    elif kind == "truncated":
        wavfile.write(path, 16000, tone)
        path.write_bytes(path.read_bytes()[:9000])
    else:
        path.write_bytes(b"ID3\x04" + bytes(200))  # an MP3's tag, not a WAV
    return path


@pytest.mark.parametrize("kind", ["1hz", "truncated", "not-wav"])
def test_a_bad_wav_is_exit_2_naming_it_before_work(tmp_path, kind):
    audio = _wav(tmp_path, kind)
    out = tmp_path / "o"
    args = ["eval", "movebox-study", "--audio", str(audio), "--out", str(out), "--quick"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert str(audio) in _reason(result)
    assert not (out / "movebox.json").exists()


@pytest.mark.parametrize(
    "metrics", [{"walk_err_cm": "3.1"}, [1.0, 2.0], {"walk_err_cm": [1.0]}, "fast"]
)
def test_a_baseline_of_the_wrong_types_is_exit_2_before_any_scenario(tmp_path, metrics):
    base = tmp_path / "base.json"
    record = {"scenario": "default", "seeds": {"scenario": 0}, "scenario_hash": "x"}
    base.write_text(json.dumps(record | {"metrics": metrics}))
    out = tmp_path / "o"
    args = ["run", str(DEFAULT_SCENARIO), "--baseline", str(base), "--out", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert str(base) in _reason(result) and "metrics" in _reason(result)
    assert not out.exists()


def test_an_existing_user_file_is_never_replaced_but_our_own_output_is(tmp_path):
    mine = tmp_path / "report.json"
    mine.write_text("my notes\n")
    motion = save_motion(generate("wave", duration_s=0.5), tmp_path / "w.npz")
    for args in (
        ["bench", "formats", "--json", str(mine)],
        ["info", str(motion), "--json", str(mine)],
        ["convert", str(motion), str(mine.with_suffix(".npz")), "--json", str(mine)],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
        assert "delete it or choose another path" in _reason(result)
        assert mine.read_text() == "my notes\n"
    ours = tmp_path / "info.json"
    for _ in range(2):  # a rerun replaces what avatarsim wrote
        result = runner.invoke(app, ["info", str(motion), "--json", str(ours)])
        assert result.exit_code == 0, result.output
    assert json.loads(ours.read_text())["frames"] > 0
    ours.write_text(ours.read_text() + " ")  # changed since: no longer ours to replace
    again = runner.invoke(app, ["info", str(motion), "--json", str(ours)])
    assert again.exit_code == 2, again.output
    converted = tmp_path / "c.bvh"
    converted.write_text("a user's BVH\n")
    result = runner.invoke(app, ["convert", str(motion), str(converted)])
    assert result.exit_code == 2 and converted.read_text() == "a user's BVH\n"

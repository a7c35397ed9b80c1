from __future__ import annotations

import errno
import json
import os
import shutil

import pytest
from typer.testing import CliRunner

from avatarsim.scripts.cli import app
from avatarsim.scripts.dataset import runner as runner_module
from tests.scripts.dataset.builders import tree_bytes, write_config

runner = CliRunner()


def test_generate_info_verify(tiny_dataset, tiny_config_path, tmp_path):
    out, report = tmp_path / "ds", tmp_path / "gen.json"
    args = ["dataset", "generate", str(tiny_config_path), "--out", str(out), "--json", str(report)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    payload = json.loads(report.read_text())
    assert (payload["shards"], payload["samples"], payload["shards_made"]) == (5, 10, 5)
    assert payload["samples_per_s"] > 0
    assert tree_bytes(out) == tree_bytes(tiny_dataset)
    again = runner.invoke(app, [*args[:-2], "--json", str(tmp_path / "again.json")])
    assert again.exit_code == 0, again.output
    assert json.loads((tmp_path / "again.json").read_text())["shards_resumed"] == 5

    info = runner.invoke(app, ["dataset", "info", str(out), "--json", str(tmp_path / "i.json")])
    assert info.exit_code == 0, info.output
    counts = json.loads((tmp_path / "i.json").read_text())["counts"]
    assert sum(c["samples"] for c in counts.values()) == 10
    verify = runner.invoke(app, ["dataset", "verify", str(out)])
    assert verify.exit_code == 0, verify.output


def test_verify_fails_with_exit_1(tiny_dataset, tmp_path):
    root = tmp_path / "ds"
    shutil.copytree(tiny_dataset, root)
    (root / "shards" / "val-000000.tar").write_bytes(b"not a shard")
    result = runner.invoke(app, ["dataset", "verify", str(root)])
    assert result.exit_code == 1
    assert "sha256 differs" in result.output


@pytest.mark.parametrize(
    "changes",
    [
        {"colour": "red"},
        {"sources": [{"kind": "builtin", "subjects": 0}]},
        {"splits": {"train": 0.5, "val": 0.1, "test": 0.1}},
        {"sources": [{"kind": "mocap", "path": "/nonexistent/mocap"}]},
    ],
)
def test_bad_configs_exit_2_writing_nothing(tmp_path, changes):
    config = write_config(tmp_path / "c.toml", **changes)
    out = tmp_path / "ds"
    result = runner.invoke(app, ["dataset", "generate", str(config), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output
    assert not out.exists()


def test_unwritable_out_exits_2(tiny_config_path, tmp_path):
    # /proc takes no new folders, whoever runs the tests (a chmod does not stop root).
    out = "/proc/avatarsim-dataset"
    result = runner.invoke(app, ["dataset", "generate", str(tiny_config_path), "--out", out])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output


def test_out_that_is_a_file_and_bad_executors_exit_2(tiny_config_path, tmp_path):
    a_file = tmp_path / "file"
    a_file.write_text("x")
    out = ["--out", str(tmp_path / "d")]
    for extra in (
        ["--out", str(a_file)],
        [*out, "--executor", "dask"],
        [*out, "--address", "auto"],  # a Ray address without --executor ray
        [*out, "--workers", "0"],
    ):
        result = runner.invoke(app, ["dataset", "generate", str(tiny_config_path), *extra])
        assert result.exit_code == 2, result.output
    assert not (tmp_path / "d").exists()


def test_a_full_disk_exits_2_and_says_how_to_resume(tiny_config_path, tmp_path, monkeypatch):
    def no_space(path, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(runner_module, "write_atomic", no_space)
    out = tmp_path / "ds"
    result = runner.invoke(app, ["dataset", "generate", str(tiny_config_path), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "No space left" in result.output and "resume" in result.output
    assert not list((out / "shards").iterdir()) and not (out / "manifest.json").exists()

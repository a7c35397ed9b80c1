"""A tiny ControllerPose dataset (fisheye keypoints + VR) and a tiny model trained on it by
the CLI, once per session."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from avatarsim.scripts.cli import app
from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.runner import generate
from tests.scripts.dataset.builders import write_config

VR_AND_FISHEYE = [{"name": "vf", "physics": False}]


def tiny_dataset(folder, devices) -> object:
    config = write_config(folder / "tiny.toml", devices=devices)
    generate(load_config(config), folder / "ds", workers=1)
    return folder / "ds"


@pytest.fixture(scope="session")
def cp_dataset(tmp_path_factory):
    return tiny_dataset(tmp_path_factory.mktemp("cp-data"), VR_AND_FISHEYE)


@pytest.fixture(scope="session")
def cp_run(tmp_path_factory, cp_dataset):
    run = tmp_path_factory.mktemp("cp-run") / "run"
    result = CliRunner().invoke(
        app,
        ["train", "controllerpose", "--data", str(cp_dataset), "--out", str(run),
         "--max-epochs", "2", "--width", "32", "--blocks", "1"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return run

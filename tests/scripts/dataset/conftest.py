"""A tiny dataset, generated once per session (in this process, one worker)."""

from __future__ import annotations

import pytest

from scripts.dataset.config import load_config
from scripts.dataset.runner import generate
from tests.scripts.dataset.builders import write_config


@pytest.fixture(scope="session")
def tiny_config_path(tmp_path_factory):
    return write_config(tmp_path_factory.mktemp("config") / "tiny.toml")


@pytest.fixture(scope="session")
def tiny_dataset(tmp_path_factory, tiny_config_path):
    root = tmp_path_factory.mktemp("tiny") / "ds"
    generate(load_config(tiny_config_path), root, workers=1)
    return root

"""A tiny dataset, generated once per session (in this process, one worker), and one local
Ray instance per session for the Ray executor's tests (Ray takes seconds to start)."""

from __future__ import annotations

import pytest

from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.runner import generate
from tests.conftest import require_module
from tests.scripts.dataset.builders import write_config


@pytest.fixture(scope="session")
def tiny_config_path(tmp_path_factory):
    return write_config(tmp_path_factory.mktemp("config") / "tiny.toml")


@pytest.fixture(scope="session")
def tiny_dataset(tmp_path_factory, tiny_config_path):
    root = tmp_path_factory.mktemp("tiny") / "ds"
    generate(load_config(tiny_config_path), root, workers=1)
    return root


@pytest.fixture(scope="session")
def local_ray():
    """A local Ray instance of 2 CPUs; the executor finds it connected and uses it."""
    ray = require_module("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    ray.shutdown()

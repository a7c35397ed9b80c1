"""Every block of Python in the README runs, as a user would paste it: in a fresh interpreter,
in an empty working folder, with ``out/ds`` a small generated dataset and ``../shared/mocap``
the real mocap (blocks that read it skip without it, and fail under ``CI=true``)."""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.runner import generate
from tests.conftest import require_module
from tests.scripts.dataset.builders import write_config

README = Path(__file__).parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)


def _title(block: str) -> str:
    names = re.findall(r"import (\w+)", block)
    return "-".join(names[:2]) or "block"


@pytest.fixture(scope="module")
def dataset_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("readme")
    devices = [
        {"name": "all", "fisheye": True, "kinect": "kinect-v2", "kinect_depth": True,
         "image_scale": 0.25},
    ]  # fmt: skip
    sources = [{"kind": "builtin", "activities": ["wave"], "subjects": 3}]
    window = {"seconds": 0.2, "fps": 30.0}
    config = write_config(root / "c.toml", window=window, devices=devices, sources=sources)
    generate(load_config(config), root / "ds", workers=1)
    return root / "ds"


PARAMS = [
    pytest.param(b, id=_title(b), marks=[pytest.mark.mocap] if "../shared/mocap" in b else [])
    for b in BLOCKS
]


@pytest.mark.parametrize("block", PARAMS)
def test_readme_python_block_runs(block, tmp_path, request):
    if "../shared/mocap" in block:
        block = block.replace("../shared/mocap", str(request.getfixturevalue("mocap_dir")))
    if "out/ds" in block:
        (tmp_path / "out").mkdir()
        (tmp_path / "out" / "ds").symlink_to(request.getfixturevalue("dataset_dir"))
    if "webdataset" in block:
        require_module("webdataset")
    env = {**os.environ, "PYTHONPATH": str(README.parent)}
    run = subprocess.run(
        [sys.executable, "-c", block], cwd=tmp_path, capture_output=True, text=True, env=env
    )
    assert run.returncode == 0, run.stderr[-3000:]


def test_every_slow_test_is_in_the_readme_slow_table():
    """Each test marked ``slow`` (never run by ``make test``; a decorator or a marked
    parameter) is a row of the README's table of what only the slow tier checks."""
    marked = {
        node.name
        for path in (README.parent / "tests").rglob("test_*.py")
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.FunctionDef)
        and any("pytest.mark.slow" in ast.unparse(d) for d in node.decorator_list)
    }
    table = README.read_text().split("| slow test |", 1)[1].split("\n\n", 1)[0]
    assert len(marked) >= 5
    assert not [name for name in sorted(marked) if f"::{name}" not in table], marked

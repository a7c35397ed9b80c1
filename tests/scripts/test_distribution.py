"""The built wheel ships what the checkout holds, under one import namespace: every data file
of the five folders (rigs, shaders, scenarios in their sub-folders, dataset configs, models)
as ``avatarsim/<folder>/...``, read back from the wheel with :mod:`zipfile`, nothing else at
the top of site-packages, dependencies as ranges; and, installed alone into a fresh venv, it
runs a shipped scenario and the README's API example from an empty folder."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
PACKAGES = ("avatar_models", "render_cams", "synthesis", "sim", "scripts")


def tracked(*paths: str) -> list[str]:
    """The checkout's files (committed or new, not ignored) under ``paths``."""
    return subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard", *paths],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> zipfile.ZipFile:
    """The wheel built from a copy of the checkout's files (no build/ or egg-info left over
    from an earlier build, which setuptools would reuse)."""
    source, out = tmp_path_factory.mktemp("source"), tmp_path_factory.mktemp("wheel")
    for name in tracked():
        if (ROOT / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, source / name)
    pip = [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation"]
    subprocess.run([*pip, "-w", str(out), str(source)], check=True, capture_output=True)
    (path,) = out.glob("avatarsim-*.whl")
    return zipfile.ZipFile(path)


def tracked_data_files() -> set[str]:
    """The non-Python files of the five folders, less the docs sources (``make docs`` reads
    them from the checkout; they are not package data)."""
    return {
        f for f in tracked(*PACKAGES) if not f.endswith(".py") and not f.startswith("scripts/docs/")
    }


def test_every_data_file_is_in_the_wheel(wheel):
    data = tracked_data_files()
    assert any(f.startswith("scripts/scenarios/smoke/") for f in data)  # the suites are there
    missing = {f"avatarsim/{f}" for f in data} - set(wheel.namelist())
    assert not missing, f"not in the wheel: {sorted(missing)}"


def test_everything_installs_under_the_avatarsim_namespace(wheel):
    """Nothing called ``sim`` or ``scripts`` at the top of site-packages."""
    tops = {name.split("/", 1)[0] for name in wheel.namelist()}
    assert {t for t in tops if not t.endswith(".dist-info")} == {"avatarsim"}


def test_runtime_dependencies_are_ranges(wheel):
    (meta,) = [n for n in wheel.namelist() if n.endswith(".dist-info/METADATA")]
    requires = [
        line.split(":", 1)[1].strip()
        for line in wheel.read(meta).decode().splitlines()
        if line.startswith("Requires-Dist:") and "extra ==" not in line
    ]
    assert requires and not [r for r in requires if "==" in r], requires


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> Path:
    """A fresh venv with only the wheel in it (``--no-deps``); its dependencies come from this
    interpreter's site-packages through a path line, which adds their folder but not the
    checkout's editable-install hook, so ``avatarsim`` can only come from the wheel."""
    venv = tmp_path_factory.mktemp("venv")
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    subprocess.run(
        [python, "-m", "pip", "install", "-q", "--no-deps", "--no-index", wheel.filename],
        check=True,
        capture_output=True,
    )
    purelib = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    deps = sysconfig.get_path("purelib")
    Path(purelib, "zz_dependencies.pth").write_text(deps + "\n")
    return venv


def test_the_installed_wheel_runs_outside_the_checkout(installed, tmp_path):
    """From an empty folder: the package imports from the venv, no top-level ``sim`` or
    ``scripts`` exists, a shipped scenario runs by its installed path, and the README's
    Python API example runs."""
    python = installed / "bin" / "python"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    probe = (
        "import importlib.util as u, avatarsim.scripts, avatarsim.sim;"
        "print(avatarsim.sim.__file__);"
        "print(u.find_spec('sim'), u.find_spec('scripts'));"
        "print(avatarsim.scripts.__path__[0])"
    )
    out = subprocess.run(
        [python, "-c", probe], cwd=tmp_path, env=env, check=True, capture_output=True, text=True
    ).stdout.split("\n")
    assert out[0].startswith(str(installed)), out[0]
    assert out[1] == "None None"
    scenario = Path(out[2]) / "scenarios" / "smoke" / "walk_physics.toml"
    run = subprocess.run(
        [installed / "bin" / "avatarsim", "run", str(scenario), "--out", "walk"],
        cwd=tmp_path, env=env, capture_output=True, text=True,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert json.loads((tmp_path / "walk" / "results.json").read_text())["passed"]
    (example,) = [b for b in re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
                  if "humanoid_for(motion)" in b]  # fmt: skip
    api = subprocess.run([python, "-c", example], cwd=tmp_path, env=env, capture_output=True)
    assert api.returncode == 0, api.stderr[-2000:]

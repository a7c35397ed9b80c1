"""The built wheel ships what the checkout holds, under one import namespace: every data file
of the five folders (rigs, shaders, scenarios in their sub-folders, dataset configs, models)
as ``avatarsim/<folder>/...``, read back from the wheel with :mod:`zipfile`, nothing else at
the top of site-packages, and dependencies as ranges."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
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
    return {f for f in tracked(*PACKAGES) if not f.endswith(".py")}


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

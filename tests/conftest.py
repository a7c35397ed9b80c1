"""Shared fixtures. Real mocap lives in ../shared/mocap (override with ``AVATARSIM_MOCAP``).

Outside CI a test whose data or optional package is missing skips; in CI (``CI=true``, set by
``.ci/run``) the same absence FAILS, because CI always has ``../shared`` and the test extras:
a missing folder there means the suite did not check what it claims. Every such test goes
through :func:`require` (the ``mocap_dir`` fixture, :func:`require_module`), and every test
that takes ``mocap_dir`` must carry the ``mocap`` marker (enforced at collection).
"""

from __future__ import annotations

import importlib
import os
from pathlib import Path
from types import ModuleType

import pytest

import avatarsim.avatar_models  # noqa: F401  (picks the headless GL backend before any GL import)

MOCAP_DIR = Path(
    os.environ.get(
        "AVATARSIM_MOCAP", Path(__file__).resolve().parents[1].parent / "shared" / "mocap"
    )
)
# What `mocap:` motion sources (shipped real-clip scenarios) read, in this process and in the
# commands tests start as subprocesses.
if MOCAP_DIR.is_dir():
    os.environ.setdefault("AVATARSIM_MOCAP", str(MOCAP_DIR))


def in_ci() -> bool:
    """Whether the suite runs in CI (``CI`` set to true/1/yes, as CI services and .ci/run do)."""
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")


def require(available: bool, what: str) -> None:
    """Skip the calling test when ``what`` is not ``available``; fail instead in CI."""
    if available:
        return
    if in_ci():
        pytest.fail(f"{what} (CI=true: required in CI, not skipped)", pytrace=False)
    pytest.skip(what)


def require_module(name: str) -> ModuleType:
    """The imported module ``name`` (an optional test dependency), under :func:`require`."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        require(False, f"optional test dependency {name!r} is not importable: {exc}")
        raise  # unreachable: require() skipped or failed


@pytest.fixture(scope="session")
def mocap_dir() -> Path:
    require(MOCAP_DIR.is_dir(), f"real mocap folder {MOCAP_DIR} is absent")
    return MOCAP_DIR


def pytest_collection_modifyitems(config, items):
    """A test that reads real mocap without the ``mocap`` marker is a collection error: the
    marker is how ``-m 'not mocap'`` deselects them and how readers find them."""
    unmarked = [
        item.nodeid
        for item in items
        if "mocap_dir" in getattr(item, "fixturenames", ()) and not item.get_closest_marker("mocap")
    ]
    if unmarked:
        raise pytest.UsageError(f"tests use mocap_dir without @pytest.mark.mocap: {unmarked}")

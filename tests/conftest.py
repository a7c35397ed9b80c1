"""Shared fixtures. Real mocap lives in ../shared/mocap; tests that need it skip without it."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import avatar_models  # noqa: F401  (picks the headless GL backend before any GL import)

MOCAP_DIR = Path(
    os.environ.get(
        "AVATARSIM_MOCAP", Path(__file__).resolve().parents[1].parent / "shared" / "mocap"
    )
)


@pytest.fixture(scope="session")
def mocap_dir() -> Path:
    if not MOCAP_DIR.is_dir():
        pytest.skip(f"real mocap folder {MOCAP_DIR} is absent")
    return MOCAP_DIR

"""Built-in takes and their noise-free Kinect streams, and the speech samples of
``../shared/audio`` (skipped when absent, as ``../shared/mocap``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.kinect import kinect_skeleton
from tests.conftest import MOCAP_DIR, require

SENSORS = ("kinect-v2", "azure-kinect")
AUDIO_DIR = MOCAP_DIR.parent / "audio"


@pytest.fixture(scope="session")
def box_truth():
    return generate("box", duration_s=2.0, fps=90.0, seed=0)


@pytest.fixture(scope="session")
def clean_kinect(box_truth):
    """Noise-free skeleton streams of the box take, by sensor."""
    return {s: kinect_skeleton(box_truth, s, noise=None) for s in SENSORS}


@pytest.fixture(scope="session")
def noisy_kinect(box_truth):
    return {s: kinect_skeleton(box_truth, s, seed=0) for s in SENSORS}


@pytest.fixture(scope="session")
def audio_dir() -> Path:
    require((AUDIO_DIR / "hello.wav").is_file(), f"speech samples {AUDIO_DIR} are absent")
    return AUDIO_DIR

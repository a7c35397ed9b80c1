"""A built-in take, its Kinect streams (tracked on the rendered depth, as MoveBox receives
them, and the exact joints for the retargeting's own error), and the speech samples of
``../shared/audio`` (skipped when absent, as ``../shared/mocap``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.kinect import Kinect, kinect_skeleton
from tests.conftest import MOCAP_DIR, require

SENSORS = ("kinect-v2", "azure-kinect")
AUDIO_DIR = MOCAP_DIR.parent / "audio"


@pytest.fixture(scope="session")
def box_truth():
    return generate("box", duration_s=2.0, fps=90.0, seed=0)


@pytest.fixture(scope="session")
def clean_kinect(box_truth):
    """Noise-free skeleton streams of the box take, by sensor: the true joints on the Kinect
    rig (no sensor), to measure the retargeting alone."""
    return {s: kinect_skeleton(box_truth, s, noise=None) for s in SENSORS}


@pytest.fixture(scope="session")
def tracked_kinect(box_truth):
    """The ``Kinect`` device's skeleton streams of the box take (tracked on its depth)."""
    streams = {s: Kinect(s).sample(box_truth, seed=0).skeleton for s in SENSORS}
    assert all(k.meta["skeleton"] == "tracker" for k in streams.values())
    return streams


@pytest.fixture(scope="session")
def audio_dir() -> Path:
    require((AUDIO_DIR / "hello.wav").is_file(), f"speech samples {AUDIO_DIR} are absent")
    return AUDIO_DIR

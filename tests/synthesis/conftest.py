"""Small CoolMoves databases built from the procedural generator (a few seconds each)."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import Motion, Skeleton
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.synthesis.base import FrameBatch, Poses, Synthesizer
from avatarsim.synthesis.coolmoves import build_database

TRAIN_SUBJECTS = (
    Subject(height_m=1.70, tempo=0.95, amplitude=1.05),
    Subject(height_m=1.82, tempo=1.05, amplitude=0.95, style="happy"),
)
TEST_SUBJECT = Subject(height_m=1.76, tempo=1.0, amplitude=1.0)
ACTIVITIES = ("box", "run")


@pytest.fixture(scope="session")
def train_motions():
    return [
        generate(a, s, 4.0, 90.0, seed=7 * i + j)
        for i, s in enumerate(TRAIN_SUBJECTS)
        for j, a in enumerate(ACTIVITIES)
    ]


@pytest.fixture(scope="session")
def small_db(train_motions):
    return build_database(train_motions)


@pytest.fixture(scope="session")
def test_motion():
    return generate("box", TEST_SUBJECT, 4.0, 90.0, seed=99)


def yaw_matrix(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class TruthReplay(Synthesizer):
    """A perfect method: the ground truth, frame by frame."""

    name = "truth"
    devices = ("hmd",)

    def __init__(self, truth: Motion):
        self.truth = truth
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self.truth.skeleton

    def reset_state(self) -> None:
        self.frame = 0

    def advance(self, frames: FrameBatch) -> Poses:
        rows = np.minimum(self.frame + np.arange(frames.size), self.truth.n_frames - 1)
        self.frame += frames.size
        return Poses(self.truth.root_pos[rows], self.truth.local_rot[rows])

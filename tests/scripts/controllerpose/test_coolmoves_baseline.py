"""CoolMoves from the VR stream alone as ``eval controllerpose``'s baseline: its database is
the train split's motions only, and it is read at the examples' own frames, on a dataset's
held-out split and on a real clip of each source."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.scripts.controllerpose.coolmoves_baseline import (
    coolmoves_positions,
    training_motions,
)
from avatarsim.scripts.controllerpose.data import load_examples, mocap_examples, split_streams
from avatarsim.scripts.dataset.torch_dataset import ShardDataset
from avatarsim.synthesis.coolmoves import build_database

SOURCES = {"cmu": "cmu", "bandai-1": "bandai/dataset-1", "bandai-2": "bandai/dataset-2"}


@pytest.fixture(scope="module")
def database(cp_dataset):
    return build_database(training_motions(cp_dataset))


def test_the_database_holds_exactly_the_train_samples_motions(cp_dataset):
    motions = training_motions(cp_dataset)
    train = list(ShardDataset(cp_dataset, split="train"))
    assert len(motions) == len(train)
    # The regenerated windows are the recorded ones: same activities, same frame counts.
    assert sorted(m.meta["activity"] for m in motions) == sorted(
        s["json"]["activity"] for s in train
    )
    assert sorted(m.n_frames for m in motions) == sorted(s["json"]["frames"] for s in train)


def test_coolmoves_is_read_at_the_examples_frames_with_its_head_on_the_headset(
    cp_dataset, database
):
    test = load_examples(cp_dataset, "test", 3)
    positions = coolmoves_positions(database, split_streams(cp_dataset, "test"), test)
    assert positions.shape == test.positions.shape and np.isfinite(positions).all()
    # The world head keypoint follows the headset: near the truth's head at the same frame
    # (the examples' truth is pelvis-relative, so compare against the recorded body17).
    truth_head = truth_world_head(cp_dataset, test)
    gap = np.linalg.norm(positions[:, INDEX["head"]] - truth_head, axis=-1)
    assert np.median(gap) < 0.1


def truth_world_head(root, examples) -> np.ndarray:
    heads = np.zeros((len(examples), 3))
    for group, sample in enumerate(ShardDataset(root, split="test")):
        rows = np.flatnonzero(examples.group == group)
        frame = np.rint(examples.time[rows] * sample["json"]["fps"]).astype(int)
        heads[rows] = sample["body17"].numpy()[frame, INDEX["head"]]
    return heads


@pytest.mark.mocap
@pytest.mark.parametrize("source", sorted(SOURCES))
def test_coolmoves_baseline_on_a_real_clip(source, mocap_dir, database):
    clips, streams = mocap_examples(mocap_dir / SOURCES[source], 1, 1.0)
    positions = coolmoves_positions(database, streams, clips)
    assert len(clips) > 0 and np.isfinite(positions).all()

"""Scenario corruptions: each name applies its sim.corrupt defect; the physics suite proves
the checks fire (scripts/scenarios/physics)."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.corruption import corrupted
from avatarsim.scripts.scenario import CORRUPTIONS


@pytest.fixture(scope="module")
def walk():
    return generate("walk", duration_s=1.0, seed=0)


def test_sink_and_float_move_the_body_by_their_documented_sizes(walk):
    dz = corrupted(walk, "sink_feet", 0).root_pos[:, 2] - walk.root_pos[:, 2]
    assert np.allclose(dz, -0.10)
    dz = corrupted(walk, "float_body", 0).root_pos[:, 2] - walk.root_pos[:, 2]
    assert np.allclose(dz, 0.15)


@pytest.mark.parametrize("defect", CORRUPTIONS)
def test_every_corruption_changes_the_motion_and_keeps_its_shape(walk, defect):
    bad = corrupted(walk, defect, 0)
    assert bad.n_frames == walk.n_frames and bad.skeleton is walk.skeleton
    changed = not (
        np.array_equal(bad.root_pos, walk.root_pos)
        and np.array_equal(bad.local_rot, walk.local_rot)
    )
    assert changed


def test_jitter_follows_the_seed(walk):
    a, b = (corrupted(walk, "add_jitter", s).root_pos for s in (0, 1))
    assert np.array_equal(a, corrupted(walk, "add_jitter", 0).root_pos)
    assert not np.array_equal(a, b)


def test_an_unknown_corruption_is_refused(walk):
    with pytest.raises(ValueError, match="unknown corruption"):
        corrupted(walk, "melt", 0)

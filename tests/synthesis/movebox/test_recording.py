"""Recording and playback: a take recorded on one avatar plays on another, crops, loops and
round-trips through BVH and NPZ."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.movebox.recording import (
    crop,
    load_recording,
    looped,
    playback,
    save_recording,
)
from avatarsim.synthesis.movebox.resize import resized


@pytest.fixture(scope="module")
def take():
    return generate("walk", Subject(height_m=1.85), duration_s=2.0, fps=30.0, seed=0)


def test_playback_on_a_smaller_avatar_keeps_rotations_and_feet_on_the_floor(take):
    small = resized(load_rig("avatar").skeleton, 1.55)
    out = playback(take, small)
    assert np.allclose(out.local_rot, take.local_rot, atol=1e-12, rtol=0)
    lowest = out.global_positions()[..., 2].min(axis=1)
    theirs = take.global_positions()[..., 2].min(axis=1)
    assert np.abs(lowest - theirs * 1.55 / 1.85).max() < 0.01


def test_playback_refuses_another_layout(take):
    with pytest.raises(SynthesisError, match="joint layout"):
        playback(take, load_rig("cmu").skeleton)


def test_crop(take):
    part = crop(take, 0.5, 1.0)
    assert part.n_frames == 16
    assert np.allclose(part.local_rot, take.local_rot[15:31], atol=1e-12, rtol=0)
    for bad in ((1.0, 0.5), (-1.0, 0.5), (5.0, 6.0)):
        with pytest.raises(SynthesisError, match="crop range"):
            crop(take, *bad)


def test_loop_lasts_and_walks_on(take):
    out = looped(take, 5.0)
    assert out.n_frames == 151
    start, stop = out.meta["loop_frames"]
    assert stop > start
    # the root keeps going forward over the seams (no jump back to the start)
    assert np.all(np.diff(out.root_pos[:, 0]) > -0.01)


@pytest.mark.parametrize("suffix", [".bvh", ".npz"])
def test_files_round_trip(tmp_path, take, suffix):
    path = save_recording(take, tmp_path / f"take{suffix}")
    back = load_recording(path)
    assert back.n_frames == take.n_frames
    assert np.allclose(back.global_positions(), take.global_positions(), atol=1e-4)

"""``on_clock``: a glitched timestamp costs one sample, not a clock of millions of ticks."""

from __future__ import annotations

import time

import numpy as np
import pytest

from avatar_models.generator import Subject, generate
from avatar_models.measure import standing_height
from render_cams import VRSetup
from synthesis.base import SynthesisError, on_clock
from synthesis.ik_baseline import IKBaseline


@pytest.fixture(scope="module")
def walk():
    motion = generate("walk", Subject(height_m=1.75), 1.0, 90.0, seed=5)
    return motion, VRSetup().sample(motion, seed=0)


@pytest.mark.parametrize("glitch_s", [1000.0, 1e5])
def test_one_glitched_timestamp_is_dropped_and_the_run_stays_fast(walk, glitch_s):
    motion, stream = walk
    ts = stream.timestamps.copy()
    ts[40] = glitch_s
    start = time.perf_counter()
    out = IKBaseline(motion.skeleton, standing_height(motion)).run(stream.replace(timestamps=ts))
    # A glitch stepped as a clock gap would be 9e4-9e6 ticks: minutes to hours. The run takes
    # 0.5 s idle and 1.4-1.9 s on a 2-core machine at load 10 (measured); 10 s separates them.
    assert time.perf_counter() - start < 10.0
    assert out.n_frames == motion.n_frames  # the glitched sample's tick is stepped as missing
    assert np.isfinite(out.root_pos).all() and np.isfinite(out.local_rot).all()
    assert out.meta["stream"]["repairs"]["clock_outliers"] == 1


def test_a_lasting_clock_jump_is_refused(walk):
    _, stream = walk
    ts = stream.timestamps + np.where(np.arange(stream.n_samples) >= 45, 1e5, 0.0)
    with pytest.raises(SynthesisError, match="clock jumps"):
        on_clock(stream.replace(timestamps=ts))


def test_a_short_pause_keeps_its_empty_ticks(walk):
    _, stream = walk
    ts = stream.timestamps + np.where(np.arange(stream.n_samples) >= 45, 0.5, 0.0)
    clocked = on_clock(stream.replace(timestamps=ts))
    assert clocked.n_samples == stream.n_samples + 45
    assert not clocked.valid[45:90].any() and clocked.valid[90:].all()

"""The ``Synthesizer`` contract: ``step`` is the method's core on a batch of one, ``run`` the
same core on the re-clocked stream; ``on_clock``: a glitched timestamp costs one sample, not a
clock of millions of ticks."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import Skeleton, quat
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import (
    FrameBatch,
    Poses,
    SynthesisError,
    Synthesizer,
    TrackingFrame,
    on_clock,
)
from avatarsim.synthesis.ik_baseline import IKBaseline


@pytest.fixture(scope="module")
def walk():
    motion = generate("walk", Subject(height_m=1.75), 1.0, 90.0, seed=5)
    return motion, VRSetup().sample(motion, seed=0)


@pytest.mark.parametrize("glitch_s", [1000.0, 1e5])
def test_one_glitched_timestamp_is_dropped_not_stepped_through(walk, glitch_s):
    motion, stream = walk
    ts = stream.timestamps.copy()
    ts[40] = glitch_s
    out = IKBaseline(motion.skeleton, standing_height(motion)).run(stream.replace(timestamps=ts))
    # One output frame per tick of the real clock: the glitch did not open a gap of
    # glitch_s * 90 ticks to step through (which is what made such runs take minutes).
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


class HeadsetCounter(Synthesizer):
    """A toy method whose state is visible in its output: the root's x is the number of
    usable headset samples so far, y the time of the latest frame it was given."""

    name = "counter"
    devices = ("hmd",)

    def __init__(self):
        self._skeleton = Skeleton(("root",), [-1], np.zeros((1, 3)))
        self.reset()

    @property
    def skeleton(self) -> Skeleton:
        return self._skeleton

    def reset_state(self) -> None:
        self.count = 0

    def advance(self, frames: FrameBatch) -> Poses:
        (hmd,) = self.device_index(frames)
        counts = self.count + np.cumsum(frames.usable()[:, hmd])
        self.count = int(counts[-1])
        root = np.stack([counts, frames.timestamps, np.zeros(frames.size)], axis=-1)
        return Poses(root, np.tile(quat.IDENTITY, (frames.size, 1, 1)))


def test_step_is_a_batch_of_one_and_skips_late_samples(walk):
    _, stream = walk
    synth = HeadsetCounter()
    order = [0, 1, 2, 1, 2, 3]  # a late and a repeated sample
    poses = [synth.step(TrackingFrame.from_stream(stream, i)) for i in order]
    assert [p.root_pos[0] for p in poses] == [1, 2, 3, 3, 3, 4]
    assert poses[3] is poses[2]  # the state did not move


def test_run_steps_every_tick_of_the_clock_and_continues_like_step(walk):
    _, stream = walk
    gap = stream.replace(valid=stream.valid & (np.arange(stream.n_samples) != 10)[:, None])
    dropped = np.delete(np.arange(stream.n_samples), 20)  # one sample never delivered
    synth = HeadsetCounter()
    out = synth.run(gap[dropped])
    assert out.n_frames == stream.n_samples  # the missing tick is a frame
    # Samples 10 (invalid) and 20 (missing) are not counted; the rest are, in order.
    ticks = np.arange(stream.n_samples)
    expected = np.cumsum((ticks != 10) & (ticks != 20))
    np.testing.assert_array_equal(out.root_pos[:, 0], expected)
    assert out.meta["method"] == "counter"
    # After run, step carries on from the state run left, and ignores what run already saw.
    later = TrackingFrame.from_stream(stream.replace(timestamps=stream.timestamps + 2.0), 0)
    assert synth.step(later).root_pos[0] == expected[-1] + 1
    assert synth.step(TrackingFrame.from_stream(stream, 5)).root_pos[0] == expected[-1] + 1


def test_a_missing_device_is_named(walk):
    _, stream = walk
    no_hmd = stream.replace(device_names=("head_set",) + stream.device_names[1:])
    with pytest.raises(SynthesisError, match="counter needs devices \\['hmd'\\]"):
        HeadsetCounter().run(no_hmd)

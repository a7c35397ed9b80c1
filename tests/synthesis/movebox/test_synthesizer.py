"""``MoveBox`` as a method: streaming equals batch, no look into the future, finite output
through tracking loss, and typed errors for unusable streams."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from avatarsim.render_cams.kinect import TrackingState
from avatarsim.render_cams.vr import VRSetup
from avatarsim.synthesis.base import SynthesisError, TrackingFrame
from avatarsim.synthesis.methods import MethodInputs, build
from avatarsim.synthesis.movebox import MoveBox


@pytest.fixture(scope="module")
def vr_stream(box_truth):
    return VRSetup().sample(box_truth, seed=0)


def test_step_equals_run(tracked_kinect, box_truth, vr_stream):
    synth = MoveBox(tracked_kinect["kinect-v2"], box_truth.skeleton)
    batch = synth.run(vr_stream)
    synth.reset()
    steps = [synth.step(TrackingFrame.from_stream(vr_stream, i)) for i in range(60)]
    assert np.array_equal(np.stack([s.local_rot for s in steps]), batch.local_rot[:60])
    assert np.array_equal(np.stack([s.root_pos for s in steps]), batch.root_pos[:60])


def test_no_kinect_frame_after_a_tick_changes_it(tracked_kinect, box_truth, vr_stream):
    kinect = tracked_kinect["azure-kinect"]
    cut = 1.0
    later = kinect.timestamps > cut
    changed = replace(kinect, positions=np.where(later[:, None, None], 5.0, kinect.positions))
    a = MoveBox(kinect, box_truth.skeleton).run(vr_stream)
    b = MoveBox(changed, box_truth.skeleton).run(vr_stream)
    before = vr_stream.timestamps <= cut
    assert np.array_equal(a.local_rot[before], b.local_rot[before])
    assert not np.array_equal(a.local_rot[~before], b.local_rot[~before])


def test_lost_joints_with_nan_data_give_finite_poses(tracked_kinect, box_truth, vr_stream):
    kinect = tracked_kinect["kinect-v2"]
    states = kinect.states.copy()
    states[10:40, :12] = TrackingState.NOT_TRACKED  # the upper body leaves the view
    positions = np.where((states == TrackingState.NOT_TRACKED)[..., None], np.nan, kinect.positions)
    lost = replace(kinect, states=states, positions=positions)
    out = MoveBox(lost, box_truth.skeleton).run(vr_stream)
    assert np.isfinite(out.local_rot).all() and np.isfinite(out.root_pos).all()


def test_unusable_streams_raise(tracked_kinect, box_truth):
    kinect = tracked_kinect["kinect-v2"]
    empty = replace(kinect, timestamps=kinect.timestamps[:0], states=kinect.states[:0])
    with pytest.raises(SynthesisError, match="no frame"):
        MoveBox(empty, box_truth.skeleton)
    never = replace(kinect, states=np.zeros_like(kinect.states))
    with pytest.raises(SynthesisError, match="NotTracked"):
        MoveBox(never, box_truth.skeleton)


def test_registry_says_which_devices_entry_to_enable(box_truth):
    inputs = MethodInputs(lambda: None, 1.75, box_truth.skeleton)
    with pytest.raises(SynthesisError, match=r"\[devices\] kinect"):
        build("movebox", inputs)


def test_record_is_the_stream_on_the_display_clock(tracked_kinect, box_truth):
    kinect = tracked_kinect["kinect-v2"]
    motion = MoveBox(kinect, box_truth.skeleton).record(30.0)
    assert motion.fps == 30.0
    assert abs(motion.duration_s - (kinect.timestamps[-1] - kinect.timestamps[0])) < 1 / 30


def test_registry_drives_a_resized_avatar_for_a_foreign_rig(tracked_kinect):
    from avatarsim.avatar_models.measure import standing_height
    from avatarsim.avatar_models.rigs import load_rig

    inputs = MethodInputs(
        lambda: None, 1.62, load_rig("cmu").skeleton, kinect=tracked_kinect["kinect-v2"]
    )
    synth = build("movebox", inputs)
    assert synth.name == "movebox" and synth.skeleton.name == "avatar"
    assert standing_height(synth.skeleton) == pytest.approx(1.62)


def test_root_steps_with_kinect_frames_unless_smoothed(tracked_kinect, box_truth, vr_stream):
    """The paper smooths rotations only (§III-A1): at 90 Hz each 30 Hz Kinect frame's root is
    shown unchanged on about three ticks; ``smooth_root`` (beyond the paper) moves it every
    tick."""
    kinect = tracked_kinect["kinect-v2"]
    shown = vr_stream.timestamps > kinect.timestamps[0]
    n_frames = np.count_nonzero(kinect.timestamps <= vr_stream.timestamps[-1])
    paper = MoveBox(kinect, box_truth.skeleton).run(vr_stream).root_pos[shown]
    smooth = MoveBox(kinect, box_truth.skeleton, smooth_root=True).run(vr_stream).root_pos[shown]
    assert root_changes(paper) <= n_frames
    assert root_changes(smooth) > 2 * n_frames


def root_changes(root: np.ndarray) -> int:
    """Ticks whose root ``(T, 3)`` differs from the tick before."""
    return int(np.count_nonzero(np.any(np.diff(root, axis=0) != 0, axis=1)))

"""Faults: controller dropout, NaN samples, out-of-order timestamps. The output stays finite
and is back within 2 cm of the fault-free output 0.5 s after the signal returns."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import VRSetup
from avatarsim.render_cams.vr import NaNSamples, Occlusion, OutOfOrder
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.coolmoves import CoolMoves
from tests.synthesis.conftest import TEST_SUBJECT

RETURN_S = 2.0


@pytest.fixture(scope="module")
def clean(test_motion):
    return VRSetup().sample(test_motion, seed=0)


@pytest.fixture(scope="module")
def reference(small_db, clean):
    return body17_positions(CoolMoves(small_db, TEST_SUBJECT.height_m).run(clean))


def _recovered(small_db, faulty, reference, after_s=RETURN_S + 0.5):
    out = CoolMoves(small_db, TEST_SUBJECT.height_m).run(faulty)
    assert np.isfinite(out.root_pos).all() and np.isfinite(out.local_rot).all()
    got = body17_positions(out)
    assert got.shape == reference.shape
    late = int(round(after_s * 90))
    return np.linalg.norm(got[late:] - reference[late:], axis=-1), got


@pytest.mark.parametrize("device", ["left_controller", "right_controller", "hmd"])
def test_one_second_dropout(small_db, clean, reference, device):
    faulty = Occlusion(device, start_s=RETURN_S - 1.0, duration_s=1.0).apply(clean, None)
    assert not faulty.valid.all()
    err, _ = _recovered(small_db, faulty, reference)
    assert err.max() < 0.02


def test_dropped_hand_holds_its_arm(small_db, clean):
    faulty = Occlusion("left_controller", start_s=1.0, duration_s=1.0).apply(clean, None)
    out = CoolMoves(small_db, TEST_SUBJECT.height_m).run(faulty)
    arm = np.flatnonzero(small_db.limb_masks[0])
    lost = slice(90, 180)
    held = out.local_rot[lost][:, arm]
    np.testing.assert_allclose(held, np.broadcast_to(held[0], held.shape), atol=1e-12)
    # ...while the rest of the body keeps moving with the right hand's matches.
    trunk = np.flatnonzero(~small_db.limb_masks.any(axis=0))
    assert np.abs(np.diff(out.local_rot[lost][:, trunk], axis=0)).max() > 1e-3


def test_nan_samples_marked_valid(small_db, clean, reference):
    nan = NaNSamples(fraction=0.1).apply(clean, np.random.default_rng(0))
    early = (clean.timestamps < RETURN_S)[:, None, None]
    faulty = clean.replace(
        positions=np.where(early, nan.positions, clean.positions),
        quaternions=np.where(early, nan.quaternions, clean.quaternions),
    )
    assert np.isnan(faulty.positions).any() and faulty.valid.all()
    err, _ = _recovered(small_db, faulty, reference)
    assert err.max() < 0.02


def test_out_of_order_and_duplicate_timestamps(small_db, clean, reference):
    faulty = OutOfOrder(swap_fraction=0.05, duplicate_fraction=0.05).apply(
        clean, np.random.default_rng(1)
    )
    assert np.any(np.diff(faulty.timestamps) <= 0)
    err, _ = _recovered(small_db, faulty, reference, after_s=0.0)
    assert err.max() < 1e-9  # repaired and re-clocked, the stream is the clean one


def test_streaming_skips_late_samples(small_db, clean):
    """A sample stamped before one already seen is skipped: it returns the pose before it,
    and the other samples give exactly the poses of the stream without the late ones."""
    faulty = OutOfOrder(swap_fraction=0.1).apply(clean, np.random.default_rng(2))
    t = faulty.timestamps
    late = np.r_[False, t[1:] <= np.maximum.accumulate(t)[:-1]]
    assert 5 <= late.sum() < 0.2 * late.size

    def stepped(stream):
        synth = CoolMoves(small_db, TEST_SUBJECT.height_m)
        poses = [synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)]
        return np.stack([p.root_pos for p in poses]), np.stack([p.local_rot for p in poses])

    root, rot = stepped(faulty)
    on_time_root, on_time_rot = stepped(faulty[np.flatnonzero(~late)])
    held = np.maximum.accumulate(np.where(late, 0, np.arange(late.size)))  # last on-time index
    np.testing.assert_array_equal(root[late], root[held[late]])
    np.testing.assert_array_equal(rot[late], rot[held[late]])
    np.testing.assert_array_equal(root[~late], on_time_root)
    np.testing.assert_array_equal(rot[~late], on_time_rot)


def test_no_tracking_at_all_still_gives_a_pose(small_db, clean):
    blind = clean.replace(valid=np.zeros_like(clean.valid), positions=clean.positions * np.nan)
    out = CoolMoves(small_db, TEST_SUBJECT.height_m).run(blind)
    assert np.isfinite(out.local_rot).all() and np.isfinite(out.root_pos).all()

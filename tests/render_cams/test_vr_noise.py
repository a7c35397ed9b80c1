"""Noise, dropout and fault models: exact shifts, statistics against their definitions."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.render_cams import DeviceError, StreamError, UnknownDeviceError, VRSetup
from avatarsim.render_cams.vr import (
    Drift,
    Dropouts,
    Latency,
    NaNSamples,
    Occlusion,
    OutOfOrder,
    PositionJitter,
    RotationJitter,
    TimestampJitter,
)
from tests.render_cams.builders import body17_motion, static_stream

RATE = 90.0


def rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def invalid_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of each run of False in a 1-D validity mask."""
    lost = np.concatenate([[0], (~mask).astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(lost))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


@pytest.fixture(scope="module")
def clean():
    return VRSetup().sample(body17_motion(seconds=2.0), seed=0)


@pytest.mark.parametrize("k", [1, 3, 9])
def test_latency_of_k_samples_shifts_by_exactly_k(clean, k):
    late = Latency(seconds=k / RATE).apply(clean, rng())
    np.testing.assert_array_equal(late.positions[k:], clean.positions[:-k])
    np.testing.assert_allclose(late.quaternions[k:], clean.quaternions[:-k], atol=1e-12)
    # Before the first sample the device reports its first pose; timestamps are unchanged.
    np.testing.assert_array_equal(late.positions[:k], np.repeat(clean.positions[:1], k, 0))
    np.testing.assert_array_equal(late.timestamps, clean.timestamps)


def test_half_sample_latency_interpolates(clean):
    late = Latency(seconds=0.5 / RATE).apply(clean, rng())
    mid = 0.5 * (clean.positions[1:] + clean.positions[:-1])
    np.testing.assert_allclose(late.positions[1:], mid, atol=1e-12)
    assert np.all(np.abs(np.linalg.norm(late.quaternions, axis=-1) - 1) < 1e-12)


def test_position_jitter_matches_sigma():
    sigma, n = 0.002, 20000
    noisy = PositionJitter(sigma).apply(static_stream(n, 1), rng())
    samples = noisy.positions.reshape(-1, 3)
    # Sample standard deviation has a relative standard error of 1 / sqrt(2 N) = 0.5 %.
    np.testing.assert_allclose(samples.std(axis=0), sigma, rtol=0.03)
    assert np.all(np.abs(samples.mean(axis=0)) < 5 * sigma / np.sqrt(n))


def test_rotation_jitter_matches_sigma():
    sigma, n = np.radians(0.5), 20000
    noisy = RotationJitter(sigma).apply(static_stream(n, 1), rng())
    angles = quat.angle(noisy.quaternions.reshape(-1, 4))
    # A rotation vector with sigma per axis has E[angle^2] = 3 sigma^2.
    assert np.sqrt(np.mean(angles**2)) == pytest.approx(np.sqrt(3) * sigma, rel=0.03)
    np.testing.assert_allclose(np.linalg.norm(noisy.quaternions, axis=-1), 1.0, atol=1e-12)


def test_drift_grows_like_a_random_walk():
    rate_m, devices = 0.01, 500
    seconds = np.array([1.0, 4.0, 9.0])
    walk = Drift(position_m_per_sqrt_s=rate_m).apply(static_stream(811, devices), rng())
    assert np.all(walk.positions[0] == 0.0)  # starts where the device is
    at = walk.positions[(seconds * RATE).astype(int)]  # (3, D, 3)
    # Variance grows linearly in time: sigma^2 t (1500 samples: ~4 % standard error).
    np.testing.assert_allclose(at.reshape(3, -1).var(axis=1), rate_m**2 * seconds, rtol=0.15)
    # Increments over disjoint intervals are independent.
    corr = np.corrcoef((at[1] - at[0]).ravel(), (at[2] - at[1]).ravel())[0, 1]
    assert abs(corr) < 4 / np.sqrt(at[0].size)


def test_yaw_drift_turns_about_up_only():
    walk = Drift(position_m_per_sqrt_s=0.0, yaw_rad_per_sqrt_s=0.05).apply(
        static_stream(900, 3), rng()
    )
    up = quat.rotate(walk.quaternions, np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(up, np.broadcast_to([0, 0, 1.0], up.shape), atol=1e-12)
    assert np.ptp(quat.yaw(walk.quaternions[:, 0])) > 0.01


def test_dropout_fraction_and_burst_lengths_as_configured():
    bursts_per_s, duration = 0.1, 1.0
    stream = static_stream(int(200 * RATE), 50)
    lost = Dropouts(bursts_per_s=bursts_per_s, duration_s=duration).apply(stream, rng())
    expected = 1 - np.exp(-bursts_per_s * duration)  # coverage of a Poisson interval process
    assert (~lost.valid).mean() == pytest.approx(expected, rel=0.1)
    runs = [r for d in range(50) for r in invalid_runs(lost.valid[:, d])]
    interior = [n for start, n in runs if start > 0 and start + n < stream.n_samples]
    assert min(interior) >= duration * RATE  # merged bursts only get longer
    # A run is a single burst when no other starts during it: probability exp(-0.1) = 0.905.
    assert np.mean(np.array(interior) == duration * RATE) > 0.85
    assert np.all(np.isnan(lost.positions[~lost.valid]))
    assert np.all(np.isnan(lost.quaternions[~lost.valid]))
    np.testing.assert_array_equal(lost.positions[lost.valid], 0.0)


def test_controller_occluded_for_one_second(clean):
    hidden = Occlusion("right_controller", start_s=0.5, duration_s=1.0).apply(clean, rng())
    right = hidden.device("right_controller")
    assert invalid_runs(hidden.valid[:, right]) == [(45, 90)]
    others = [d for d in range(3) if d != right]
    assert hidden.valid[:, others].all()
    np.testing.assert_array_equal(hidden.positions[:, others], clean.positions[:, others])


def test_timestamp_jitter_leaves_poses_alone():
    stream = static_stream(20000, 1)
    jittered = TimestampJitter(sigma_s=0.001).apply(stream, rng())
    assert np.std(jittered.timestamps - stream.timestamps) == pytest.approx(0.001, rel=0.03)
    np.testing.assert_array_equal(jittered.positions, stream.positions)
    # A sigma of a whole sample period reorders timestamps, which validate() reports.
    wild = TimestampJitter(sigma_s=1 / RATE).apply(stream, rng())
    with pytest.raises(StreamError, match="strictly increase"):
        wild.validate()
    wild.repaired().validate()


def test_nan_samples_break_the_contract_and_repair_fixes_them(clean):
    faulty = NaNSamples(fraction=0.05, devices=("hmd",)).apply(clean, rng())
    hmd = faulty.device("hmd")
    nan = np.isnan(faulty.positions).any(-1)
    assert nan[:, hmd].mean() == pytest.approx(0.05, abs=0.04)
    assert not nan[:, hmd + 1 :].any() and faulty.valid.all()
    with pytest.raises(StreamError, match="marked valid but hold NaN"):
        faulty.validate()
    fixed = faulty.repaired().validate()
    np.testing.assert_array_equal(fixed.valid, ~nan)
    assert fixed.meta["repairs"]["invalidated"] == nan.sum()


def test_out_of_order_and_duplicates_are_undone_by_repair(clean):
    faulty = OutOfOrder(swap_fraction=0.1, duplicate_fraction=0.05).apply(clean, rng())
    assert faulty.n_samples > clean.n_samples
    assert np.any(np.diff(faulty.timestamps) < 0)
    with pytest.raises(StreamError):
        faulty.validate()
    fixed = faulty.repaired().validate()
    np.testing.assert_array_equal(fixed.timestamps, clean.timestamps)
    np.testing.assert_array_equal(fixed.positions, clean.positions)
    assert fixed.meta["repairs"]["dropped_samples"] == faulty.n_samples - clean.n_samples


def test_noise_on_one_device_leaves_the_others_untouched(clean):
    for model in (
        PositionJitter(0.01, devices=("left_controller",)),
        RotationJitter(0.1, devices=("left_controller",)),
        Drift(0.1, 0.1, devices=("left_controller",)),
        Latency(0.05, devices=("left_controller",)),
        Dropouts(5.0, 0.1, devices=("left_controller",)),
    ):
        out = model.apply(clean, rng())
        left = clean.device("left_controller")
        for d in (0, 2):
            np.testing.assert_array_equal(out.positions[:, d], clean.positions[:, d])
            np.testing.assert_array_equal(out.quaternions[:, d], clean.quaternions[:, d])
        changed = [
            not np.array_equal(getattr(out, key)[:, left], getattr(clean, key)[:, left])
            for key in ("positions", "quaternions")
        ]
        assert any(changed), type(model).__name__


def test_composed_noise_is_deterministic_and_recorded():
    noise = (
        Latency(0.02),
        Drift(),
        PositionJitter(),
        RotationJitter(),
        Dropouts(0.5, 0.2),
        TimestampJitter(),
        NaNSamples(0.01),
        OutOfOrder(0.01, 0.01),
    )
    setup = VRSetup(noise=noise)
    motion = body17_motion(seconds=1.0)
    a, b = setup.sample(motion, seed=5), setup.sample(motion, seed=5)
    for key in ("timestamps", "positions", "quaternions", "valid"):
        assert getattr(a, key).tobytes() == getattr(b, key).tobytes()
    assert [n["type"] for n in a.meta["noise"]] == [type(m).__name__ for m in noise]
    assert a.meta["noise"][0]["seconds"] == 0.02
    # Adding a model after the others leaves their draws unchanged.
    longer = VRSetup(noise=(*noise[:3], RotationJitter(0.5))).sample(motion, seed=5)
    shorter = VRSetup(noise=noise[:3]).sample(motion, seed=5)
    np.testing.assert_array_equal(longer.positions, shorter.positions)


def test_zero_noise_changes_nothing(clean):
    for model in (PositionJitter(0.0), Drift(0.0), Latency(0.0), Dropouts(0.0, 1.0)):
        out = model.apply(clean, rng())
        np.testing.assert_array_equal(out.positions, clean.positions)
        assert out.valid.all()


@pytest.mark.parametrize(
    "make",
    [
        lambda: PositionJitter(-0.001),
        lambda: RotationJitter(float("nan")),
        lambda: Latency(-0.01),
        lambda: Drift(position_m_per_sqrt_s=-1.0),
        lambda: Dropouts(bursts_per_s=-1.0),
        lambda: TimestampJitter(-1.0),
        lambda: NaNSamples(1.5),
        lambda: OutOfOrder(swap_fraction=-0.1),
        lambda: OutOfOrder(devices=("hmd",)),
    ],
)
def test_bad_noise_settings_are_rejected(make):
    with pytest.raises(DeviceError):
        make()


def test_noise_on_a_device_the_stream_lacks_names_the_available_ones(clean):
    with pytest.raises(UnknownDeviceError, match="available: hmd"):
        PositionJitter(devices=("back_tracker",)).apply(clean, rng())


def test_latency_needs_a_rate():
    stream = static_stream(10, 1).replace(meta={})
    with pytest.raises(DeviceError, match="rate_hz"):
        Latency(0.01).apply(stream, rng())

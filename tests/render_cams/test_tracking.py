"""TrackingStream: contract checks, lookup, slicing, repair and npz files."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from avatarsim.avatar_models import AvatarsimError
from avatarsim.render_cams import StreamError, StreamFormatError, TrackingStream, UnknownDeviceError
from tests.render_cams.builders import static_stream


def test_device_lookup():
    stream = static_stream(5, 3)
    assert stream.device("dev2") == 2
    with pytest.raises(UnknownDeviceError, match="'hmd'; available: dev0, dev1, dev2"):
        stream.device("hmd")
    with pytest.raises(KeyError):  # also a KeyError, for dict-like callers
        stream.device("hmd")


def test_arrays_are_read_only_copies():
    positions = np.zeros((4, 1, 3))
    stream = static_stream(4, 1).replace(positions=positions)
    positions[0, 0, 0] = 1.0
    assert stream.positions[0, 0, 0] == 0.0
    with pytest.raises(ValueError):
        stream.positions[0, 0, 0] = 1.0


@pytest.mark.parametrize(
    "change",
    [
        {"positions": np.zeros((5, 2, 3))},
        {"quaternions": np.zeros((5, 1, 3))},
        {"valid": np.ones(5, bool)},
        {"timestamps": np.zeros((5, 1))},
    ],
)
def test_wrong_shapes_are_rejected(change):
    with pytest.raises(StreamError, match="must have shape"):
        static_stream(5, 1).replace(**change)


def test_duplicate_device_names_are_rejected():
    with pytest.raises(StreamError, match="unique"):
        static_stream(5, 2).replace(device_names=("a", "a"))


def test_validate_finds_each_broken_rule():
    stream = static_stream(5, 2)
    assert stream.validate() is stream
    ts = stream.timestamps.copy()
    ts[[1, 2]] = ts[[2, 1]]
    with pytest.raises(StreamError, match="sample 2 at 0.011111 s follows 0.022222 s"):
        stream.replace(timestamps=ts).validate()
    with pytest.raises(StreamError, match="strictly increase"):
        stream.replace(timestamps=np.zeros(5)).validate()
    ts = stream.timestamps.copy()
    ts[3] = np.nan
    with pytest.raises(StreamError, match="NaN/inf"):
        stream.replace(timestamps=ts).validate()
    pos = stream.positions.copy()
    pos[3, 1, 0] = np.nan
    with pytest.raises(StreamError, match="device 'dev1' at sample 3"):
        stream.replace(positions=pos).validate()
    # The same NaN is fine where the sample is marked invalid.
    valid = stream.valid.copy()
    valid[3, 1] = False
    stream.replace(positions=pos, valid=valid).validate()
    with pytest.raises(StreamError, match="unit length"):
        stream.replace(quaternions=2 * stream.quaternions).validate()
    assert issubclass(StreamError, AvatarsimError)


def test_slicing_by_index_and_time():
    stream = static_stream(90, 2)
    assert stream[10:20].n_samples == 10
    window = stream.between(0.5, 0.6)
    np.testing.assert_allclose(window.timestamps, np.arange(45, 54) / 90.0)
    assert window.meta == stream.meta and window.device_names == stream.device_names


def test_repaired_sorts_stably_and_keeps_first_duplicate():
    stream = static_stream(6, 1)
    ts = np.array([0.0, 0.2, 0.1, 0.1, np.nan, 0.3])
    marker = np.arange(6.0)[:, None, None] * np.ones((1, 1, 3))
    fixed = stream.replace(timestamps=ts, positions=marker).repaired()
    np.testing.assert_array_equal(fixed.timestamps, [0.0, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(fixed.positions[:, 0, 0], [0, 2, 1, 5])  # first 0.1 arrival
    assert fixed.meta["repairs"] == {
        "reordered": 1,
        "dropped_samples": 2,
        "invalidated": 0,
        "clock_outliers": 0,
    }
    fixed.validate()


@pytest.mark.parametrize("glitched", [[0], [40], [88, 89], [30, 31, 32]])
def test_repaired_drops_timestamps_far_from_the_stream_clock(glitched):
    stream = static_stream(90, 1)
    ts = stream.timestamps.copy()
    ts[glitched] = 1000.0 + np.arange(len(glitched)) / 90.0
    fixed = stream.replace(timestamps=ts).repaired()
    np.testing.assert_array_equal(fixed.timestamps, np.delete(stream.timestamps, glitched))
    assert fixed.meta["repairs"]["clock_outliers"] == len(glitched)
    assert fixed.meta["repairs"]["dropped_samples"] == len(glitched)


def test_repaired_keeps_both_sides_of_a_pause_in_delivery():
    stream = static_stream(90, 1)
    ts = stream.timestamps + np.where(np.arange(90) >= 45, 5.0, 0.0)  # 5 s without samples
    fixed = stream.replace(timestamps=ts).repaired()
    np.testing.assert_array_equal(fixed.timestamps, ts)
    assert fixed.meta["repairs"]["clock_outliers"] == 0


def test_npz_round_trip_keeps_nan_and_meta(tmp_path):
    stream = static_stream(20, 2)
    pos = stream.positions.copy()
    pos[3] = np.nan
    valid = stream.valid.copy()
    valid[3] = False
    stream = stream.replace(positions=pos, valid=valid, meta={"seed": 4, "rate_hz": 90.0})
    path = stream.to_npz(tmp_path / "sub" / "s.npz")
    back = TrackingStream.from_npz(path)
    assert back.device_names == stream.device_names and back.meta == stream.meta
    for key in ("timestamps", "positions", "quaternions", "valid"):
        assert getattr(back, key).tobytes() == getattr(stream, key).tobytes(), key
    # Atomic write: nothing but the target is left behind; rewriting gives the same bytes.
    assert [p.name for p in path.parent.iterdir()] == ["s.npz"]
    first = path.read_bytes()
    stream.to_npz(path)
    assert path.read_bytes() == first


def test_malformed_files_raise_stream_format_error(tmp_path):
    with pytest.raises(StreamFormatError, match="no such stream file"):
        TrackingStream.from_npz(tmp_path / "missing.npz")
    garbage = tmp_path / "garbage.npz"
    garbage.write_bytes(b"not a zip at all")
    with pytest.raises(StreamFormatError, match="garbage.npz: unreadable npz"):
        TrackingStream.from_npz(garbage)
    partial = tmp_path / "partial.npz"
    np.savez(partial, timestamps=np.zeros(3))
    with pytest.raises(StreamFormatError, match="lacks"):
        TrackingStream.from_npz(partial)
    good = static_stream(4, 1).to_npz(tmp_path / "good.npz")
    wrong_shape = tmp_path / "wrong.npz"
    with np.load(good) as data:
        arrays = {k: data[k] for k in data.files}
    np.savez(wrong_shape, **{**arrays, "positions": np.zeros((4, 2, 3))})
    with pytest.raises(StreamFormatError, match="must have shape"):
        TrackingStream.from_npz(wrong_shape)
    bad_meta = tmp_path / "meta.npz"
    np.savez(bad_meta, **{**arrays, "meta": np.array("{not json")})
    with pytest.raises(StreamFormatError, match="unreadable"):
        TrackingStream.from_npz(bad_meta)
    with zipfile.ZipFile(good) as zf:
        assert sorted(zf.namelist())[0] == "device_names.npy"

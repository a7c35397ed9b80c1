from __future__ import annotations

import io
import tarfile

import numpy as np

from avatarsim.scripts.dataset.shards import read_samples, shard_bytes


def _samples():
    rng = np.random.default_rng(0)
    return [
        (
            f"s{k:07d}",
            {"b": rng.normal(size=(3, 2)).astype(np.float32), "a": np.arange(k + 1)},
            {"k": k, "z": [1.5]},
        )
        for k in range(3)
    ]


def test_same_samples_same_bytes_in_webdataset_layout(tmp_path):
    data = shard_bytes(_samples())
    assert data == shard_bytes(_samples())
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        members = tar.getmembers()
    assert [m.name for m in members[:3]] == ["s0000000.a.npy", "s0000000.b.npy", "s0000000.json"]
    assert {(m.mtime, m.uid, m.gid, m.uname, m.gname, m.mode) for m in members} == {
        (0, 0, 0, "", "", 0o644)
    }
    path = tmp_path / "x.tar"
    path.write_bytes(data)
    read = list(read_samples(path))
    assert [k for k, _ in read] == ["s0000000", "s0000001", "s0000002"]
    for (_, arrays, meta), (_, sample) in zip(_samples(), read, strict=True):
        assert sample["json"] == meta
        for name, value in arrays.items():
            assert sample[name].dtype == value.dtype
            np.testing.assert_array_equal(sample[name], value)

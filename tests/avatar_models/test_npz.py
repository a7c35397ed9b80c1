"""NPZ: exact round trip, atomic writes, malformed files."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats.npz import read_npz, write_npz
from avatarsim.avatar_models.skeleton import Skeleton
from tests.avatar_models.test_bvh import random_motion


def test_round_trip_is_exact(tmp_path):
    motion = random_motion(np.random.default_rng(3), n_joints=6, n_frames=9)
    sk = motion.skeleton
    limited = Skeleton(
        sk.names, sk.parents, sk.offsets, sk.is_site, {"j1": {"rx": (-0.5, 1.25)}}, "demo"
    )
    motion = motion.replace(skeleton=limited, fps=90.0, meta={"seed": 3, "activity": "walk"})
    path = write_npz(motion, tmp_path / "m.npz")
    back = read_npz(path)
    assert back.skeleton.names == sk.names and back.skeleton.name == "demo"
    assert back.skeleton.limits == {"j1": {"rx": (-0.5, 1.25)}}
    np.testing.assert_array_equal(back.skeleton.parents, sk.parents)
    np.testing.assert_array_equal(back.skeleton.offsets, sk.offsets)
    np.testing.assert_array_equal(back.skeleton.is_site, sk.is_site)
    np.testing.assert_array_equal(back.root_pos, motion.root_pos)
    # Motion re-normalises quaternions on construction, which may move the last bit.
    np.testing.assert_allclose(back.local_rot, motion.local_rot, rtol=0, atol=1e-15)
    assert back.fps == 90.0 and back.meta == {"seed": 3, "activity": "walk"}
    assert list(tmp_path.iterdir()) == [path]


def test_malformed_npz_files(tmp_path):
    motion = random_motion(np.random.default_rng(0))
    good = write_npz(motion, tmp_path / "good.npz")
    cases = {
        "garbage.npz": b"not a zip at all",
        "empty.npz": b"",
        "truncated.npz": good.read_bytes()[:200],
    }
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
    np.savez(tmp_path / "missing.npz", names=np.array(["a"]))
    with np.load(good) as d:
        arrays = {k: d[k] for k in d.files}
    np.savez(tmp_path / "version.npz", **{**arrays, "version": np.array(99)})
    np.savez(tmp_path / "shape.npz", **{**arrays, "local_rot": arrays["local_rot"][:, :2]})
    np.savez(tmp_path / "nan.npz", **{**arrays, "root_pos": arrays["root_pos"] * np.nan})
    np.savez(tmp_path / "json.npz", **{**arrays, "meta_json": np.array("{oops")})
    for name in [*cases, "missing.npz", "version.npz", "shape.npz", "nan.npz", "json.npz"]:
        with pytest.raises(MotionFormatError) as err:
            read_npz(tmp_path / name)
        assert err.value.path == str(tmp_path / name), name

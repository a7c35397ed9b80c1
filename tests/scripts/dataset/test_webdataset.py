"""A generated dataset read by WebDataset itself (``webdataset.WebDataset``, the client the
README names), every entry decoded with the shipped handler to the README table's key,
dtype and shape; depth stays 16-bit millimetres."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from avatarsim.scripts.dataset.config import load_config
from avatarsim.scripts.dataset.runner import generate
from avatarsim.scripts.dataset.shards import decode_entry, read_samples
from tests.conftest import require_module
from tests.scripts.dataset.builders import write_config

README = Path(__file__).parents[3] / "README.md"
T, TV, TK, N = 7, 19, 7, 3  # 0.2 s at 30 Hz (both ends), VR at 90 Hz, images every 3rd frame
D, C, J = 6, 4, 25  # headset, 2 controllers, 3 trackers; 4 cameras; Kinect V2 joints
EXPECTED = {  # the README's dataset table: key -> (dtype, shape)
    "body17.npy": ("float32", (T, 17, 3)),
    "body17_angles.npy": ("float32", (T, 43)),
    "qpos.npy": ("float32", (T, None)),
    "vr_time.npy": ("float32", (TV,)),
    "vr_pos.npy": ("float32", (TV, D, 3)),
    "vr_quat.npy": ("float32", (TV, D, 4)),
    "vr_valid.npy": ("bool", (TV, D)),
    "fisheye_uv.npy": ("float32", (T, C, 17, 2)),
    "fisheye_conf.npy": ("float32", (T, C, 17)),
    "fisheye_detected.npy": ("bool", (T, C, 17)),
    "fisheye_uv_projected.npy": ("float32", (T, C, 17, 2)),
    "fisheye_in_view.npy": ("bool", (T, C, 17)),
    "fisheye_view_uv.npy": ("float32", (T, 4, 17, 2)),
    "fisheye_view_conf.npy": ("float32", (T, 4, 17)),
    "fisheye_view_detected.npy": ("bool", (T, 4, 17)),
    "fisheye_lens_covered.npy": ("bool", (T, C)),
    "fisheye_w2c.npy": ("float32", (T, C, 4, 4)),
    "kinect_pos.npy": ("float32", (TK, J, 3)),
    "kinect_quat.npy": ("float32", (TK, J, 4)),
    "kinect_state.npy": ("int8", (TK, J)),
    "fisheye_image_frames.npy": ("int32", (N,)),
    "fisheye_image.{camera}.{n:04d}.png": ("uint8", (120, 160, 3)),
    "kinect_depth_frames.npy": ("int32", (N,)),
    "kinect_depth.{n:04d}.png": ("uint16", (424, 512)),
    "kinect_parts.{n:04d}.png": ("uint8", (424, 512)),
    "contact.npy": ("bool", (T, 2)),
    "penetration_m.npy": ("float32", (T,)),
    "skate_m_s.npy": ("float32", (T, 2)),
}


def _pattern(key: str) -> str:
    """The README's name of an entry: camera and frame number as placeholders."""
    key = re.sub(r"^fisheye_image\.[^.]+\.\d{4}\.", "fisheye_image.{camera}.{n:04d}.", key)
    return re.sub(r"^kinect_(depth|parts)\.\d{4}\.", r"kinect_\1.{n:04d}.", key)


@pytest.fixture(scope="module")
def every_channel(tmp_path_factory):
    """One shard of 0.2 s samples with every channel: VR with trackers, fisheye keypoints and
    PNG images, Kinect V2 skeleton, depth and part labels, physics labels."""
    root = tmp_path_factory.mktemp("wds")
    devices = [
        {"name": "all", "trackers": True, "fisheye_images": "png", "kinect": "kinect-v2",
         "kinect_depth": True, "kinect_parts": True, "image_scale": 0.25},
    ]  # fmt: skip
    sources = [{"kind": "builtin", "activities": ["wave"], "subjects": 3}]
    config = write_config(
        root / "c.toml", window={"seconds": 0.2, "fps": 30.0}, devices=devices, sources=sources
    )
    generate(load_config(config), root / "ds", workers=1)
    return sorted((root / "ds").rglob("*.tar"))[0]


def test_webdataset_reads_every_entry_to_the_readme_dtypes_and_shapes(every_channel):
    wds = require_module("webdataset")
    ours = dict(read_samples(every_channel))
    read = list(wds.WebDataset(str(every_channel), shardshuffle=False).decode(decode_entry))
    assert [s["__key__"] for s in read] == list(ours)
    readme = README.read_text()
    for sample in read:
        entries = {k: v for k, v in sample.items() if not k.startswith("__")}
        assert isinstance(entries.pop("json"), dict)
        assert {_pattern(k) for k in entries} == set(EXPECTED)
        for key, value in entries.items():
            dtype, shape = EXPECTED[_pattern(key)]
            assert value.dtype == dtype, key
            assert len(value.shape) == len(shape), key
            assert all(s is None or s == v for s, v in zip(shape, value.shape, strict=True)), key
            assert f"`{_pattern(key)}`" in readme, f"README's dataset table lacks {key}"
            np.testing.assert_array_equal(value, ours[sample["__key__"]][key.removesuffix(".npy")])
        # Depth in millimetres: the performer's pixels about where the sensor record puts them
        # (the default image decoders would give 0-255 or 0-1 here).
        performer_mm = 1000 * sample["json"]["channels"]["kinect"]["performer_depth_m_median"]
        depth = entries["kinect_depth.0000.png"].astype(float)
        assert 500 < performer_mm < 4500 and np.any(np.abs(depth - performer_mm) < 100)
        # skate_m_s is NaN exactly where a foot is not in contact (README).
        assert np.array_equal(np.isnan(entries["skate_m_s.npy"]), ~entries["contact.npy"])

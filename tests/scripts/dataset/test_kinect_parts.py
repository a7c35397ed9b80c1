"""The ``kinect_parts`` channel and the shipped ``kinect-parts-small`` config: a tiny dataset
of it generated and read back from its shard, the label images aligned with the depth."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.config import ConfigError
from avatarsim.scripts.dataset.config import SourceConfig, from_dict, load_config
from avatarsim.scripts.dataset.plan import plan_samples
from avatarsim.scripts.dataset.runner import generate
from avatarsim.scripts.dataset.shards import read_samples

SHIPPED = Path(__file__).parents[3] / "scripts" / "datasets" / "kinect-parts-small.toml"


@pytest.fixture(scope="module")
def tiny_parts(tmp_path_factory):
    """The shipped config cut to one built-in subject's wave, 0.2 s, seen from the front and
    from behind: 2 samples of 7 frames, depth and labels on frames 0, 3, 6."""
    config = load_config(SHIPPED)
    devices = tuple(d for d in config.devices if d.name in ("front", "back"))
    tiny = dataclasses.replace(
        config,
        window=dataclasses.replace(config.window, seconds=0.2),
        sources=(SourceConfig(kind="builtin", activities=("wave",), subjects=1),),
        devices=devices,
        splits={"train": 1.0, "val": 0.0, "test": 0.0},
    )
    root = tmp_path_factory.mktemp("parts")
    generate(tiny, root, workers=1)
    return [s for shard in sorted(root.rglob("*.tar")) for _, s in read_samples(shard)]


def test_label_images_come_back_aligned_with_the_depth(tiny_parts):
    assert len(tiny_parts) == 2
    for sample in tiny_parts:
        meta = sample["json"]["channels"]["kinect"]
        assert meta["parts"]["names"][1 + INDEX["head"]] == "head"
        depths = sorted(k for k in sample if k.startswith("kinect_depth."))
        parts = sorted(k for k in sample if k.startswith("kinect_parts."))
        assert len(parts) == len(depths) == 3
        performer_mm = 1000 * meta["performer_depth_m_median"]
        for d_key, p_key in zip(depths, parts, strict=True):
            depth, label = sample[d_key], sample[p_key]
            assert label.dtype == np.uint8 and label.shape == depth.shape == (424, 512)
            body = label > 0
            assert body.sum() > 2000 and label.max() <= 17
            # a labelled pixel has a depth reading, on the performer (within 0.5 m of them)
            assert np.all(depth[body] > 0)
            assert abs(np.median(depth[body].astype(float)) - performer_mm) < 500
            # image rows grow downwards: the head's pixels above the knees' and ankles'
            rows = np.nonzero(body)[0]
            head = rows[label[body] == 1 + INDEX["head"]]
            legs = [1 + INDEX[j] for j in ("l_knee", "r_knee", "l_ankle", "r_ankle")]
            feet = rows[np.isin(label[body], legs)]
            assert head.size and feet.size and np.median(head) < np.median(feet) - 100


def test_the_back_view_swaps_the_image_sides_of_the_left_and_right_parts(tiny_parts):
    """Seen from the front, the performer's left hand is on the image's right (their left
    faces the sensor's right); from behind, on its left."""
    sides = {}
    for sample in tiny_parts:
        label = sample["kinect_parts.0000.png"]
        cols = np.nonzero(label)[1]
        values = label[label > 0]
        left = np.median(cols[values == 1 + INDEX["l_wrist"]])
        right = np.median(cols[values == 1 + INDEX["r_wrist"]])
        sides[sample["json"]["channels"]["kinect"]["yaw_deg"]] = left > right
    assert sides == {0.0: True, 180.0: False}


def test_parts_need_the_depth_they_are_aligned_with():
    bad = {"name": "x", "kinect": "kinect-v2", "kinect_parts": True}
    with pytest.raises(ConfigError, match="kinect_parts needs kinect_depth"):
        from_dict({"name": "d", "sources": [{"kind": "builtin", "subjects": 1}], "devices": [bad]})


@pytest.mark.mocap
def test_the_shipped_config_finds_its_real_clips(mocap_dir, monkeypatch):
    monkeypatch.setenv("AVATARSIM_MOCAP", str(mocap_dir))
    clips = {s.window.clip for s in plan_samples(load_config(SHIPPED)) if s.window.clip}
    assert {Path(c).name for c in clips} == {
        "13_33.bvh",
        "dataset-1_walk_normal_001.bvh",
    }

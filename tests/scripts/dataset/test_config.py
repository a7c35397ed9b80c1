from __future__ import annotations

from dataclasses import field, fields, make_dataclass, replace
from pathlib import Path

import pytest

from avatarsim.scripts.dataset.config import (
    ConfigError,
    DeviceSetConfig,
    config_hash,
    from_dict,
    load_config,
)
from tests.scripts.dataset.builders import TINY, write_config


def test_tiny_config_loads_with_defaults(tmp_path):
    config = load_config(write_config(tmp_path / "c.toml"))
    assert config.devices[0].vr and config.devices[0].fisheye  # defaults
    assert config.sources[0].windows == 1
    assert config.with_seed(9).seed == 9 and config_hash(config.with_seed(9)) != config_hash(config)
    assert from_dict(config.as_dict()) == config  # a manifest's copy reads back the same


@pytest.mark.parametrize(
    "changes, reason",
    [
        ({"colour": "red"}, "unknown key 'colour'"),
        ({"window": {"seconds": 1.0, "fsp": 30}}, "unknown key 'fsp'"),
        ({"sources": [{"kind": "builtin", "subjects": 2, "speed": 1}]}, "unknown key 'speed'"),
        ({"sources": [{"kind": "builtin", "subjects": 0}]}, "empty source"),
        ({"sources": []}, "no [[sources]]"),
        ({"sources": [{"kind": "builtin", "activities": ["fly"], "subjects": 1}]}, "'fly'"),
        ({"splits": {"train": 0.8, "val": 0.1, "test": 0.2}}, "sum to 1"),
        ({"splits": {"train": 0.9, "holdout": 0.1}}, "unknown split"),
        ({"devices": [{"name": "a", "kinect": "kinect-v3"}]}, "kinect must be"),
        ({"samples_per_shard": 0}, "samples_per_shard"),
        ({"devices": [{"name": "a", "fisheye_images": "gif"}]}, "fisheye_images must be"),
        ({"devices": [{"name": "a", "fisheye": False, "fisheye_images": "png"}]}, "needs fish"),
        ({"devices": [{"name": "a", "kinect_depth": True}]}, "needs a kinect"),
        ({"devices": [{"name": "a", "image_stride": 0}]}, "image_stride"),
        ({"devices": [{"name": "a", "image_scale": 10.0}]}, "image_scale"),
    ],
)
def test_bad_configs_are_config_errors(tmp_path, changes, reason):
    with pytest.raises(ConfigError, match=reason.replace("[", r"\[").replace("]", r"\]")):
        load_config(write_config(tmp_path / "c.toml", **changes))


def test_unreadable_and_invalid_toml(tmp_path):
    with pytest.raises(ConfigError, match="cannot read"):
        load_config(tmp_path / "absent.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("name = ")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_config(bad)
    with pytest.raises(ConfigError, match="name is required"):
        from_dict({k: v for k, v in TINY.items() if k != "name"})


def test_relative_mocap_folders_are_relative_to_the_config(tmp_path):
    sources = [{"kind": "mocap", "path": "clips"}, {"kind": "mocap", "path": "/abs/clips"}]
    config = load_config(write_config(tmp_path / "c.toml", sources=sources))
    assert [s.path for s in config.sources] == [str(tmp_path / "clips"), "/abs/clips"]


def test_a_key_added_later_at_its_default_leaves_the_hash():
    """A device-set key that a later version adds (a new channel, off by default) must not
    change the identity of datasets made before it: they still resume and verify."""
    later = make_dataclass(
        "LaterDeviceSet",
        [("new_channel", bool, field(default=False))],
        bases=(DeviceSetConfig,),
        frozen=True,
    )
    config = from_dict(TINY)
    device = config.devices[0]
    with_new = later(**{f.name: getattr(device, f.name) for f in fields(device)})
    assert config_hash(replace(config, devices=(with_new,))) == config_hash(config)
    switched_on = replace(with_new, new_channel=True)
    assert config_hash(replace(config, devices=(switched_on,))) != config_hash(config)


def test_a_kinect_dataset_of_the_oracle_skeleton_is_not_taken_for_a_tracked_one():
    """Hashes of the configs as the version before ``kinect_skeleton`` computed them (its
    Kinect skeletons were the oracle's): a config with a Kinect hashes otherwise now, so its
    old shards neither resume nor verify; one without (the shipped controllerpose-small)
    keeps its hash."""
    assert config_hash(from_dict(TINY)) != (
        "3037dbfb6aa0cfe3253906a7ec112ce17b1ed5c921f2eae3d4bc028755d640ac"
    )
    shipped = Path(__file__).parents[3] / "scripts" / "datasets" / "controllerpose-small.toml"
    assert config_hash(load_config(shipped)) == (
        "76fd492f3ab920076b6e571d7cbceaddeb5776061620dd1efbdb727b2f5076a1"
    )

from __future__ import annotations

from collections import Counter

import pytest

from avatarsim.scripts.dataset.config import ConfigError, from_dict
from avatarsim.scripts.dataset.plan import assign_splits, plan_samples, plan_shards
from tests.scripts.dataset.builders import TINY


@pytest.mark.parametrize("n", [1, 3, 5, 10, 26])
def test_every_group_gets_one_split_in_proportion(n):
    groups = [f"g{k}" for k in range(n)]
    splits = assign_splits(groups, {"train": 0.8, "val": 0.1, "test": 0.1}, seed=1)
    assert sorted(splits) == sorted(groups)
    counts = Counter(splits.values())
    assert sum(counts.values()) == n
    if n >= 3:  # every split with a share gets a group when there are enough
        assert set(counts) == {"train", "val", "test"}
    if n >= 10:
        assert abs(counts["train"] - 0.8 * n) < 1.0
    assert assign_splits(list(reversed(groups)), {"train": 0.8, "val": 0.1, "test": 0.1}, 1) == (
        splits
    )


@pytest.mark.parametrize("splits", [{"train": 1.0}, {"train": 0.5, "test": 0.5}])
def test_a_split_left_out_of_the_config_gets_no_samples(splits):
    config = from_dict({**TINY, "splits": splits})
    planned = Counter(s.split for s in plan_samples(config))
    assert set(planned) == set(splits)  # the others are empty, not an error
    assert sum(planned.values()) == len(plan_samples(from_dict(TINY)))


def test_plan_is_deterministic_and_held_out_subjects_stay_out_of_train():
    config = from_dict(TINY)
    samples = plan_samples(config)
    assert samples == plan_samples(config)
    # 5 subjects x 2 activities x 1 window x 1 device set
    assert len(samples) == 10 and len({s.key for s in samples}) == 10
    split_of = {}
    for s in samples:
        assert split_of.setdefault(s.window.group, s.split) == s.split
    assert {s.split for s in samples} == {"train", "val", "test"}
    assert len({s.seed for s in samples}) == 10  # every sample its own seed
    other_seed = plan_samples(config.with_seed(4))
    assert [s.seed for s in other_seed] != [s.seed for s in samples]


def test_shards_hold_one_split_in_plan_order():
    config = from_dict(TINY)
    samples = plan_samples(config)
    shards = plan_shards(config, samples)
    flat = [s for shard in shards for s in shard.samples]
    assert sorted(s.index for s in flat) == list(range(len(samples)))
    for shard in shards:
        assert 1 <= len(shard.samples) <= config.samples_per_shard
        assert {s.split for s in shard.samples} == {shard.split}
        assert shard.name.startswith(shard.split + "-")


def test_mocap_source_errors(tmp_path):
    missing = {**TINY, "sources": [{"kind": "mocap", "path": str(tmp_path / "nope")}]}
    with pytest.raises(ConfigError, match="no such folder"):
        plan_samples(from_dict(missing))
    empty = {**TINY, "sources": [{"kind": "mocap", "path": str(tmp_path)}]}
    with pytest.raises(ConfigError, match="empty source"):
        plan_samples(from_dict(empty))


@pytest.mark.mocap
def test_mocap_split_by_performer_keeps_performers_whole(mocap_dir):
    config = from_dict(
        {
            **TINY,
            "sources": [
                {
                    "kind": "mocap",
                    "path": str(mocap_dir / "cmu"),
                    "split_by": "performer",
                    "windows": 2,
                }
            ],
        }
    )
    samples = plan_samples(config)
    assert len(samples) == 9 * 2  # CLIPS.md: 9 CMU clips
    by_performer = {}
    for s in samples:
        assert s.window.group.startswith("performer:")
        assert by_performer.setdefault(s.window.group, s.split) == s.split

from __future__ import annotations

import torch
from torch.utils.data import DataLoader

from avatarsim.scripts.dataset.manifest import read_manifest
from avatarsim.scripts.dataset.shards import read_samples
from avatarsim.scripts.dataset.torch_dataset import ShardDataset


def _keys(loader):
    return [sample["__key__"] for sample in loader]


def _train_keys(root):
    manifest = read_manifest(root)
    return [
        key
        for e in manifest["shards"]
        if e["split"] == "train"
        for key, _ in read_samples(root / e["file"])
    ]


def test_two_workers_read_every_sample_once(tiny_dataset):
    expected = _train_keys(tiny_dataset)
    dataset = ShardDataset(tiny_dataset, "train", shuffle_buffer=3, seed=1)
    keys = _keys(DataLoader(dataset, batch_size=None, num_workers=2))
    assert len(keys) == len(expected) == len(dataset)
    assert sorted(keys) == sorted(expected)


def test_shuffling_is_seeded_and_epochs_differ(tiny_dataset):
    ordered = _keys(ShardDataset(tiny_dataset, "train"))
    assert ordered == _train_keys(tiny_dataset)
    shuffled = ShardDataset(tiny_dataset, "train", shuffle_buffer=4, seed=7)
    first = _keys(shuffled)
    assert first == _keys(ShardDataset(tiny_dataset, "train", shuffle_buffer=4, seed=7))
    shuffled.set_epoch(1)
    orders = {tuple(first), tuple(_keys(shuffled))}
    for seed in range(8):
        orders.add(tuple(_keys(ShardDataset(tiny_dataset, "train", shuffle_buffer=4, seed=seed))))
    assert len(orders) > 2 and all(sorted(o) == sorted(ordered) for o in orders)


def test_samples_are_tensors_with_their_description(tiny_dataset):
    sample = next(iter(ShardDataset(tiny_dataset, "val")))
    assert isinstance(sample["body17"], torch.Tensor) and sample["body17"].shape[1:] == (17, 3)
    assert sample["json"]["split"] == "val" and sample["json"]["key"] == sample["__key__"]


def test_loader_workers_give_the_samples_one_process_reads(tiny_dataset):
    alone = {s["__key__"]: s for s in ShardDataset(tiny_dataset, "train")}
    loader = ShardDataset(tiny_dataset, "train").loader(num_workers=2)
    read = list(loader)
    assert sorted(s["__key__"] for s in read) == sorted(alone) and len(loader) == len(alone)
    for sample in read:
        expected = alone[sample["__key__"]]
        assert sample.keys() == expected.keys()
        for name, value in sample.items():
            if isinstance(value, torch.Tensor):
                assert value.dtype == expected[name].dtype and torch.equal(value, expected[name])
            else:
                assert value == expected[name]


def test_set_epoch_reaches_persistent_workers(tiny_dataset):
    """The epoch's order as fresh workers read it, from workers started an epoch earlier."""

    def fresh(epoch):
        dataset = ShardDataset(tiny_dataset, "train", shuffle_buffer=4, seed=3)
        dataset.set_epoch(epoch)
        return _keys(dataset.loader(num_workers=2))

    dataset = ShardDataset(tiny_dataset, "train", shuffle_buffer=4, seed=3)
    persistent = DataLoader(dataset, batch_size=None, num_workers=2, persistent_workers=True)
    loader = dataset.loader(num_workers=2)
    orders = []
    for epoch in range(3):
        dataset.set_epoch(epoch)
        orders.append(_keys(loader))
        assert orders[-1] == fresh(epoch) == _keys(persistent)
    assert len({tuple(o) for o in orders}) > 1

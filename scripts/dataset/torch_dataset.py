"""A torch ``IterableDataset`` that streams a dataset's shards.

``ShardDataset(DIR, split="train", shuffle_buffer=1000, seed=0)`` yields one sample at a
time as a dict: every array as a ``torch.Tensor`` (``body17``, ``qpos``, ``vr_pos``...) and
``"json"`` with the sample's description. Shards are split across ``DataLoader`` workers
(worker ``i`` of ``n`` reads shards ``i, i + n, ...`` of the epoch's shard order), so every
sample is read once per epoch, by one worker. Shuffling is two-level, as WebDataset does it:
the shard order per epoch from ``(seed, epoch)``, then a buffer of ``shuffle_buffer`` samples
per worker from ``(seed, epoch, worker)``; ``shuffle_buffer=0`` reads in order. Call
:meth:`set_epoch` before each epoch for a new order.

Samples differ in length only where a mocap clip was shorter than the window; batch with
``batch_size=None`` or a collate function that pads in that case.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import IterableDataset, get_worker_info

from avatarsim.scripts.dataset.config import SPLITS
from avatarsim.scripts.dataset.manifest import DatasetError, read_manifest
from avatarsim.scripts.dataset.schema import checked_samples


class ShardDataset(IterableDataset):
    """The samples of one split of a dataset folder (module docstring)."""

    def __init__(
        self, root: str | Path, split: str = "train", shuffle_buffer: int = 0, seed: int = 0
    ) -> None:
        if split not in SPLITS:
            raise DatasetError(f"unknown split {split!r}; splits: {', '.join(SPLITS)}")
        if shuffle_buffer < 0:
            raise DatasetError(f"shuffle_buffer must be 0 or more, got {shuffle_buffer}")
        self.root = Path(root)
        manifest = read_manifest(self.root)
        entries = [s for s in manifest["shards"] if s["split"] == split]
        self.shards = [self.root / s["file"] for s in entries]
        self.shard_samples = [s["samples"] for s in entries]
        self.samples = manifest["counts"][split]["samples"]
        self.shuffle_buffer = shuffle_buffer
        self.seed = seed
        self.epoch = 0

    def set_epoch(self, epoch: int) -> None:
        self.epoch = epoch

    def __len__(self) -> int:
        return self.samples

    def worker_shards(self) -> list[tuple[Path, int]]:
        """This worker's shards for the current epoch, each with its manifest's count."""
        info = get_worker_info()
        worker, workers = (0, 1) if info is None else (info.id, info.num_workers)
        order = np.arange(len(self.shards))
        if self.shuffle_buffer:
            order = np.random.default_rng([self.seed, self.epoch]).permutation(order)
        return [(self.shards[i], self.shard_samples[i]) for i in order[worker::workers]]

    def __iter__(self) -> Iterator[dict[str, Any]]:
        info = get_worker_info()
        rng = np.random.default_rng([self.seed, self.epoch, 0 if info is None else info.id])
        samples = (
            as_torch(key, sample)
            for path, count in self.worker_shards()
            for key, sample in checked_samples(path, count)
        )
        if not self.shuffle_buffer:
            yield from samples
            return
        buffer: list[dict[str, Any]] = []
        for sample in samples:
            if len(buffer) < self.shuffle_buffer:
                buffer.append(sample)
                continue
            k = int(rng.integers(len(buffer)))
            buffer[k], sample = sample, buffer[k]
            yield sample
        for k in rng.permutation(len(buffer)):
            yield buffer[k]


def as_torch(key: str, sample: dict[str, Any]) -> dict[str, Any]:
    """A decoded shard sample with its arrays as tensors and its ``__key__``."""
    out: dict[str, Any] = {"__key__": key}
    for name, value in sample.items():
        out[name] = torch.from_numpy(value) if isinstance(value, np.ndarray) else value
    return out

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

With worker processes, read through :meth:`ShardDataset.loader` rather than a bare
``DataLoader``: a sample is some twenty small arrays, and a ``DataLoader`` worker hands each
tensor over in its own shared-memory segment, which cost more than decoding the sample (two
workers read at a fraction of one process's rate). ``loader`` has the workers send the
arrays as numpy, pickled through the pipe with the sample, and makes the tensors here.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader, IterableDataset, get_worker_info

from avatarsim.scripts.dataset.config import SPLITS
from avatarsim.scripts.dataset.manifest import DatasetError, read_manifest
from avatarsim.scripts.dataset.schema import checked_samples


class ShardDataset(IterableDataset):
    """The samples of one split of a dataset folder (module docstring)."""

    def __init__(
        self,
        root: str | Path,
        split: str = "train",
        shuffle_buffer: int = 0,
        seed: int = 0,
        tensors: bool = True,
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
        # In shared memory, so set_epoch reaches persistent DataLoader workers (each holds a
        # copy of the dataset made when it started).
        self._epoch = torch.zeros((), dtype=torch.int64).share_memory_()
        self.tensors = tensors  # False: numpy arrays, as the workers of loader() send them

    @property
    def epoch(self) -> int:
        return int(self._epoch)

    def set_epoch(self, epoch: int) -> None:
        """The epoch whose shard order and shuffle the next pass reads (workers included)."""
        self._epoch.fill_(int(epoch))

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
        convert = as_torch if self.tensors else with_key
        samples = (
            convert(key, sample)
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

    def loader(self, num_workers: int = 0, **options: Any) -> ShardLoader:
        """The samples through a ``DataLoader`` with ``num_workers`` processes (module
        docstring), as tensors; ``options`` go to the ``DataLoader`` (``batch_size`` and
        ``collate_fn`` excepted: one sample at a time). Iterate it once per epoch."""
        return ShardLoader(self, num_workers, options)


class ShardLoader:
    """One sample at a time from :class:`ShardDataset` read in worker processes that send
    numpy arrays; their tensors are made in this process. Workers persist across epochs."""

    def __init__(self, dataset: ShardDataset, num_workers: int, options: dict[str, Any]):
        if {"batch_size", "collate_fn"} & set(options):
            raise DatasetError("loader() gives one sample at a time: no batch_size/collate_fn")
        self.dataset = dataset
        source = copy.copy(dataset)
        source.tensors = False
        self._source = source
        options.setdefault("persistent_workers", num_workers > 0)
        self._loader = DataLoader(
            source, batch_size=None, collate_fn=_as_sent, num_workers=num_workers, **options
        )

    def __len__(self) -> int:
        return len(self.dataset)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        for sample in self._loader:
            yield as_torch(sample.pop("__key__"), sample)


def _as_sent(sample: dict[str, Any]) -> dict[str, Any]:
    """The DataLoader's collate for :class:`ShardLoader`: the sample as the worker read it
    (the default would turn its arrays into tensors in the worker)."""
    return sample


def with_key(key: str, sample: dict[str, Any]) -> dict[str, Any]:
    """A decoded shard sample, numpy arrays as they are, with its ``__key__``."""
    return {"__key__": key, **sample}


def as_torch(key: str, sample: dict[str, Any]) -> dict[str, Any]:
    """A decoded shard sample with its arrays as tensors and its ``__key__``."""
    out: dict[str, Any] = {"__key__": key}
    for name, value in sample.items():
        out[name] = torch.from_numpy(value) if isinstance(value, np.ndarray) else value
    return out

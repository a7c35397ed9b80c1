"""Synthetic datasets: ``avatarsim dataset generate|info|verify|preview``.

One concept per module:

- :mod:`.config`: the TOML schema (:func:`load_config`, :class:`ConfigError`);
- :mod:`.plan`: the deterministic list of samples and their shards;
- :mod:`.motion_source`: the motion window of one planned sample;
- :mod:`.channels`: what a sample records, one function per device or label set;
- :mod:`.sample`: one sample's arrays and JSON (ground truth plus its channels);
- :mod:`.shards`: WebDataset-layout tar shards, byte-deterministic;
- :mod:`.manifest`: per-shard sidecars and the dataset manifest;
- :mod:`.executors`: where shards are made (a local process pool or Ray);
- :mod:`.runner`: shards made by an executor, written atomically here, resume, progress;
- :mod:`.verify`: hashes, counts, nothing lost or duplicated, no split leak;
- :mod:`.torch_dataset`: a torch ``IterableDataset`` over the shards;
- :mod:`.preview`: a picture sheet of random samples with their ground-truth skeleton.
"""

from avatarsim.avatar_models.lazy_exports import lazy_exports

_EXPORTS = {
    "DatasetConfig": ".config",
    "load_config": ".config",
    "generate": ".runner",
    "GenerateResult": ".runner",
    "read_manifest": ".manifest",
    "read_samples": ".shards",
    "VerifyReport": ".verify",
    "verify_dataset": ".verify",
    "ShardDataset": ".torch_dataset",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

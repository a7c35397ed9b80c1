"""Generate a dataset; a shard is the unit of work.

Each shard is made whole in memory by an executor (:mod:`.executors`: a local process pool
or Ray), then written here, in this process, to a temporary name and ``os.replace``d, then
its sidecar likewise (:mod:`.manifest`): a killed run leaves whole shards, at most some
temporary files (removed by the next run) and no sidecar for a shard it did not finish.
Resuming skips every shard whose tar's sha256 matches its sidecar and makes the rest; as
a shard's bytes depend on its planned samples alone, the result is byte-identical to an
uninterrupted run, whatever the worker count or executor. The manifest is written last.

A write that fails (a full disk, a folder made read-only) stops the run cleanly with a
:class:`DatasetError`: the shards written so far stay and the next run resumes from them.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable, Iterator
from contextlib import closing, contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avatarsim.avatar_models.fileio import write_atomic, write_json
from avatarsim.scripts.dataset.config import DatasetConfig, config_hash
from avatarsim.scripts.dataset.executors import check_executor, run
from avatarsim.scripts.dataset.manifest import (
    SHARD_DIR,
    STATE_FILE,
    DatasetError,
    build_manifest,
    done_sidecar,
    read_json,
    shard_path,
    state,
    write_manifest,
    write_sidecar,
)
from avatarsim.scripts.dataset.plan import ShardSpec, plan_samples, plan_shards
from avatarsim.scripts.dataset.sample import make_sample
from avatarsim.scripts.dataset.shards import shard_bytes


@dataclass(frozen=True)
class GenerateResult:
    """What a run did: ``shards``/``samples``/``frames`` of the whole dataset, ``made`` shards
    and ``made_samples`` this run (the rest were resumed), wall ``seconds``."""

    shards: int
    samples: int
    frames: int
    made: int
    made_samples: int
    seconds: float
    manifest: dict[str, Any]


@dataclass(frozen=True)
class MadeShard:
    """A shard made in memory: its tar ``data`` and what its sidecar says of it."""

    name: str
    split: str
    data: bytes
    samples: int
    frames: int
    groups: list[str]


def make_shard(config: DatasetConfig, shard: ShardSpec) -> MadeShard:
    """Shard ``shard`` of ``config``, in memory (no file is touched: any executor runs it)."""
    chash = config_hash(config)
    entries = []
    for spec in shard.samples:
        arrays, meta = make_sample(config, spec, chash)
        entries.append((spec.key, arrays, meta))
    return MadeShard(
        name=shard.name,
        split=shard.split,
        data=shard_bytes(entries),
        samples=len(entries),
        frames=sum(meta["frames"] for _, _, meta in entries),
        groups=sorted({meta["group"] for _, _, meta in entries}),
    )


def store_shard(root: Path, made: MadeShard) -> dict[str, Any]:
    """Write ``made`` and then its sidecar into ``root`` (atomically); return the sidecar.

    Raises:
        DatasetError: the write failed (nothing of this shard is left half-written).
    """
    tar = shard_path(root, made.name)
    sidecar = {
        "name": made.name,
        "file": f"{SHARD_DIR}/{tar.name}",
        "split": made.split,
        "sha256": hashlib.sha256(made.data).hexdigest(),
        "bytes": len(made.data),
        "samples": made.samples,
        "frames": made.frames,
        "groups": made.groups,
    }
    with resumable_writes(root, f"shard {made.name}"):
        write_atomic(tar, made.data)
        write_sidecar(root, sidecar)
    return sidecar


@contextmanager
def resumable_writes(root: Path, what: str) -> Iterator[None]:
    """Turn a failed write of ``what`` (``OSError``: a full disk, lost permissions) into a
    :class:`DatasetError` that says the run can be resumed."""
    try:
        yield
    except OSError as exc:
        raise DatasetError(
            f"cannot write {what} in {root}: {exc.strerror or exc}; what was written so far "
            "is kept: free space or fix permissions, then run generate again to resume"
        ) from None


def prepare(root: Path, config: DatasetConfig) -> None:
    """Make ``root`` ready: new, or a run of the same config to resume.

    Raises:
        DatasetError: ``root`` holds other files or a dataset of another config.
    """
    if root.is_dir() and any(root.iterdir()):
        if not (root / STATE_FILE).is_file():
            raise DatasetError(
                f"--out {root} is not empty and holds no dataset; choose an empty folder"
            )
        previous = read_json(root / STATE_FILE, "dataset state")
        if previous.get("config_hash") != config_hash(config):
            raise DatasetError(
                f"--out {root} holds a dataset of another config or seed (config hash "
                f"{str(previous.get('config_hash'))[:12]}); choose another folder"
            )
    with resumable_writes(root, "the dataset folder"):
        (root / SHARD_DIR).mkdir(parents=True, exist_ok=True)
        for stale in (*root.glob(".*.tmp"), *(root / SHARD_DIR).glob(".*.tmp")):
            stale.unlink(missing_ok=True)  # left by a killed run
        if not (root / STATE_FILE).is_file():
            write_json(root / STATE_FILE, state(config))


def generate(
    config: DatasetConfig,
    root: Path,
    workers: int = 1,
    on_start: Callable[[int, int], None] | None = None,
    on_shard: Callable[[int], None] | None = None,
    executor: str = "local",
    address: str | None = None,
) -> GenerateResult:
    """Generate (or resume) the dataset of ``config`` in ``root`` (module docstring).

    Args:
        workers: shards made at once (processes or Ray tasks); local 1 makes them here.
        on_start: called with (samples in all, samples already done) before any work.
        on_shard: called with the samples of each shard as it completes.
        executor: ``"local"`` or ``"ray"`` (:func:`scripts.dataset.executors.run`).
        address: the Ray cluster to attach to (``"auto"``, ``"ray://HEAD:10001"``).

    Raises:
        DatasetError: ``root`` is foreign, or a write failed (resume later).
        ExecutorError: the executor cannot run.
    """
    start = time.perf_counter()
    check_executor(executor, workers, address)  # before anything is written
    shards = plan_shards(config, plan_samples(config))
    prepare(root, config)
    sidecars = {s.name: done_sidecar(root, s.name) for s in shards}
    todo = [s for s in shards if sidecars[s.name] is None]
    if on_start is not None:
        done = sum(len(s.samples) for s in shards if sidecars[s.name] is not None)
        on_start(sum(len(s.samples) for s in shards), done)
    items = [(config, shard) for shard in todo]
    # closing: a failed write stops the executor now, not when the traceback is dropped
    with closing(run(make_shard, items, executor, workers, address)) as made_shards:
        for made in made_shards:
            sidecars[made.name] = store_shard(root, made)
            if on_shard is not None:
                on_shard(made.samples)
    manifest = build_manifest(config, [sidecars[s.name] for s in shards])
    with resumable_writes(root, "the manifest"):
        write_manifest(root, manifest)
    return GenerateResult(
        shards=len(shards),
        samples=manifest["samples"],
        frames=manifest["frames"],
        made=len(todo),
        made_samples=sum(len(s.samples) for s in todo),
        seconds=time.perf_counter() - start,
        manifest=manifest,
    )

"""Generate a dataset with a local process pool; a shard is the unit of work.

Each shard is made whole in memory, written to a temporary name and ``os.replace``d, then
its sidecar likewise (:mod:`.manifest`): a killed run leaves whole shards, at most some
temporary files (removed by the next run) and no sidecar for a shard it did not finish.
Resuming skips every shard whose tar's sha256 matches its sidecar and makes the rest; as
a shard's bytes depend on its planned samples alone, the result is byte-identical to an
uninterrupted run, whatever the worker count. The manifest is written last.

Workers are spawned (no state inherited from the parent), run BLAS single-threaded (the
pool is the parallelism) and exit when the parent dies, so a ``kill -9`` of ``generate``
leaves no orphan writing into the folder.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from avatar_models.fileio import write_atomic, write_json
from scripts.dataset.config import DatasetConfig, config_hash
from scripts.dataset.manifest import (
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
from scripts.dataset.plan import ShardSpec, plan_samples, plan_shards
from scripts.dataset.sample import make_sample
from scripts.dataset.shards import sha256_file, shard_bytes

PARENT_POLL_S = 0.5


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


def write_shard(root: Path, config: DatasetConfig, shard: ShardSpec) -> dict[str, Any]:
    """Make shard ``shard`` of ``config`` in ``root`` and return its sidecar."""
    chash = config_hash(config)
    entries = []
    for spec in shard.samples:
        arrays, meta = make_sample(config, spec, chash)
        entries.append((spec.key, arrays, meta))
    tar = shard_path(root, shard.name)
    write_atomic(tar, shard_bytes(entries))
    sidecar = {
        "name": shard.name,
        "file": f"{SHARD_DIR}/{tar.name}",
        "split": shard.split,
        "sha256": sha256_file(tar),
        "bytes": tar.stat().st_size,
        "samples": len(entries),
        "frames": sum(meta["frames"] for _, _, meta in entries),
        "groups": sorted({meta["group"] for _, _, meta in entries}),
    }
    write_sidecar(root, sidecar)
    return sidecar


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
    (root / SHARD_DIR).mkdir(parents=True, exist_ok=True)
    for stale in (*root.glob(".*.tmp"), *(root / SHARD_DIR).glob(".*.tmp")):
        stale.unlink(missing_ok=True)  # left by a killed run
    if not (root / STATE_FILE).is_file():
        write_json(root / STATE_FILE, state(config))


def _watch_parent(parent: int) -> None:
    """Pool initializer: one BLAS thread, and exit when the parent process is gone."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def generate(
    config: DatasetConfig,
    root: Path,
    workers: int = 1,
    on_start: Callable[[int, int], None] | None = None,
    on_shard: Callable[[int], None] | None = None,
) -> GenerateResult:
    """Generate (or resume) the dataset of ``config`` in ``root`` (module docstring).

    Args:
        workers: processes; 1 makes the shards in this process.
        on_start: called with (samples in all, samples already done) before any work.
        on_shard: called with the samples of each shard as it completes.
    """
    start = time.perf_counter()
    shards = plan_shards(config, plan_samples(config))
    prepare(root, config)
    sidecars = {s.name: done_sidecar(root, s.name) for s in shards}
    todo = [s for s in shards if sidecars[s.name] is None]
    if on_start is not None:
        done = sum(len(s.samples) for s in shards if sidecars[s.name] is not None)
        on_start(sum(len(s.samples) for s in shards), done)
    if workers <= 1:
        for shard in todo:
            sidecars[shard.name] = write_shard(root, config, shard)
            if on_shard is not None:
                on_shard(len(shard.samples))
    else:
        pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=get_context("spawn"),
            initializer=_watch_parent,
            initargs=(os.getpid(),),
        )
        try:
            futures = [pool.submit(write_shard, root, config, s) for s in todo]
            for future in as_completed(futures):
                sidecar = future.result()
                sidecars[sidecar["name"]] = sidecar
                if on_shard is not None:
                    on_shard(sidecar["samples"])
        finally:
            # On an error or SIGTERM: finish the shards being written, start no others.
            pool.shutdown(wait=True, cancel_futures=True)
    manifest = build_manifest(config, [sidecars[s.name] for s in shards])
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

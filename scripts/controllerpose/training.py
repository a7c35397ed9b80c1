"""``avatarsim train controllerpose``: a dataset folder in, a run folder out.

``RUN/checkpoint.pt`` (:mod:`synthesis.controllerpose.checkpoint`, saved after every epoch),
``RUN/loss.png`` (train and validation curves) and ``RUN/train.json`` (config, history,
timing). A run folder that holds a checkpoint of the same dataset (manifest sha256) and
config resumes it, with the new stopping rule (``--max-epochs``, ``--time-budget``,
``--patience`` may grow); one of another dataset or config is refused (another ``--out``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.fileio import write_json
from avatarsim.scripts.controllerpose.data import load_examples, manifest_sha256
from avatarsim.scripts.controllerpose.figures import plt, save_png
from avatarsim.synthesis.controllerpose.checkpoint import FILE, CheckpointError, load
from avatarsim.synthesis.controllerpose.network import NetConfig
from avatarsim.synthesis.controllerpose.train import TrainConfig, train

# What may change between a run and its resumption: how long it goes on.
STOPPING = ("max_epochs", "time_budget_s", "patience")


def same_run(train_config: dict) -> dict:
    """The training config without :data:`STOPPING` (a run's identity)."""
    return {k: v for k, v in train_config.items() if k not in STOPPING}


def resumable(out: Path, net: NetConfig, config: TrainConfig, sha: str):
    """The checkpoint in ``out`` to resume, or None for a fresh run.

    Raises:
        CheckpointError: ``out`` holds a run of another dataset or config, or files but no
            run (training would write among, and over, someone else's files).
    """
    if not (out / FILE).is_file():
        if out.is_dir() and any(out.iterdir()):
            raise CheckpointError(f"{out} is not empty and holds no run; choose an empty --out")
        return None
    previous = load(out)
    if previous.manifest_sha256 != sha or same_run(previous.train) != same_run(config.as_dict()):
        raise CheckpointError(
            f"{out} holds a run of another dataset or training config; choose another --out"
        )
    if previous.net != net:
        raise CheckpointError(f"{out} holds a run of another network ({previous.net})")
    return previous


def machine_memory_bytes() -> int:
    """This machine's physical memory."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_fits(net: NetConfig, config: TrainConfig, memory: int | None = None) -> None:
    """Before any work: training ``net`` needs less than ``memory`` bytes (default: the
    machine's), by :meth:`~synthesis.controllerpose.network.NetConfig.training_bytes`.

    Raises:
        AvatarsimError: the estimate, the memory and the sizes that make it.
    """
    memory = machine_memory_bytes() if memory is None else memory
    need = net.training_bytes(config.batch_size)
    if need > memory:
        raise AvatarsimError(
            f"a network of --width {net.width} and --blocks {net.blocks} "
            f"({net.state_size():,} numbers) needs about {need / 2**30:.1f} GiB to train, "
            f"more than this machine's {memory / 2**30:.1f} GiB; choose fewer blocks or a "
            "smaller width"
        )


def plot_losses(history: list[dict[str, float]], path: Path) -> None:
    """Train and validation loss per epoch (log scale) into ``path`` (PNG)."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    epochs = [h["epoch"] for h in history]
    for key, ax, unit in (("angle_mse", axes[0], "rad²"), ("position_mse", axes[1], "m²")):
        for split in ("train", "val"):
            values = [h.get(f"{split}_{key}") for h in history]
            if all(v is not None for v in values):
                ax.plot(epochs, values, label=split)
        ax.set(xlabel="epoch", ylabel=f"{key} ({unit})", yscale="log")
        ax.legend()
    save_png(fig, path)


def run_training(
    data: Path,
    out: Path,
    net: NetConfig,
    config: TrainConfig,
    frame_stride: int,
    progress: Callable[[str], None],
) -> dict[str, Any]:
    """Loads the train and val splits of ``data``, trains (or resumes) into ``out``, writes
    the curves and summary; returns the summary."""
    t0 = time.perf_counter()
    sha = manifest_sha256(data)
    previous = resumable(out, net, config, sha)
    train_set = load_examples(data, "train", frame_stride)
    val_set = load_examples(data, "val", frame_stride)
    train_set.features.check_finite(f"{data} train split")
    val_set.features.check_finite(f"{data} val split")
    load_s = time.perf_counter() - t0
    progress(f"{len(train_set)} train, {len(val_set)} val examples ({load_s:.0f} s to load)")

    def on_epoch(record: dict) -> None:
        plot_losses(checkpoint_history + [record], out / "loss.png")
        checkpoint_history.append(record)
        progress(
            f"epoch {record['epoch']}: train {record['train_loss']:.4g}, "
            f"val {record['val_loss']:.4g}, val position rmse "
            f"{record['val_position_mse'] ** 0.5 * 100:.2f} cm, {record['elapsed_s']:.0f} s"
        )

    checkpoint_history: list[dict] = list(previous.history) if previous else []
    out.mkdir(parents=True, exist_ok=True)
    checkpoint = train(train_set, val_set, net, config, sha, out, on_epoch, previous)
    best = min(checkpoint.history, key=lambda h: h["val_loss"])
    summary = {
        "data": str(data),
        "manifest_sha256": sha,
        "net": net.as_dict(),
        "train": config.as_dict(),
        "frame_stride": frame_stride,
        "examples": {"train": len(train_set), "val": len(val_set)},
        "epochs": checkpoint.epoch,
        "best_epoch": best["epoch"],
        "best_val": best,
        "load_s": load_s,
        "train_s": checkpoint.history[-1]["elapsed_s"],
        "resumed": previous is not None,
        "history": checkpoint.history,
    }
    write_json(out / "train.json", summary)
    return summary

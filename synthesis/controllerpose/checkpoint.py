"""ControllerPose checkpoints: one file that holds what inference and resuming need.

``checkpoint.pt`` (``torch.save``, written atomically) holds the feature layout
(:data:`~.features.LAYOUT`), the network's config and weights (the best on validation so
far, and the latest with the optimiser for resuming), the feature normaliser, the bone
lengths template, the training config and seed, the dataset manifest's sha256, the epoch
and the loss history: tensors and plain Python data only (arrays are stored as tensors).

A checkpoint is data, never code: :func:`load` reads it with ``torch.load(weights_only=True)``
(no object is constructed from the file, nothing in it runs) and checks every field against
:mod:`.checkpoint_schema` (layout, sizes, layer shapes, finite weights) before use.
"""

from __future__ import annotations

import os
import pickle
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from avatarsim.synthesis.controllerpose.checkpoint_schema import (
    FORMAT,
    CheckpointError,
    check_payload,
)
from avatarsim.synthesis.controllerpose.features import LAYOUT
from avatarsim.synthesis.controllerpose.network import LiftingNet, NetConfig
from avatarsim.synthesis.controllerpose.normaliser import Normaliser

FILE = "checkpoint.pt"
__all__ = ["FILE", "Checkpoint", "CheckpointError", "load", "untrained"]


@dataclass
class Checkpoint:
    """A trained (or training) model and what came with it (module docstring).

    Attributes:
        net: the network's sizes.
        best_weights: the weights with the lowest validation loss so far.
        normaliser: the features' normaliser.
        template_lengths: ``(17,)`` mean bone lengths per metre of standing height.
        train: the training config (a dict; see :class:`~.train.TrainConfig`).
        manifest_sha256: the training dataset's manifest hash.
        epoch: epochs done.
        history: per epoch: train and validation losses, seconds.
        resume: latest weights, optimiser and scheduler state, and early-stopping counters.
    """

    net: NetConfig
    best_weights: dict[str, torch.Tensor]
    normaliser: Normaliser
    template_lengths: np.ndarray
    train: dict[str, Any]
    manifest_sha256: str
    epoch: int
    history: list[dict[str, float]]
    resume: dict[str, Any]

    def model(self) -> LiftingNet:
        """The best network, in eval mode."""
        model = LiftingNet(self.net)
        model.load_state_dict(self.best_weights)
        return model.eval()

    def save(self, folder: Path) -> Path:
        """Writes ``folder/checkpoint.pt`` atomically; returns its path."""
        folder.mkdir(parents=True, exist_ok=True)
        payload = {
            "format": FORMAT,
            "layout": LAYOUT,
            "net": self.net.as_dict(),
            "best_weights": self.best_weights,
            "normaliser": {k: torch.from_numpy(v) for k, v in self.normaliser.state().items()},
            "template_lengths": torch.from_numpy(np.asarray(self.template_lengths, np.float64)),
            "train": self.train,
            "seed": self.train.get("seed"),
            "manifest_sha256": self.manifest_sha256,
            "epoch": self.epoch,
            "history": self.history,
            "resume": self.resume,
        }
        path = folder / FILE
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".checkpoint-", suffix=".tmp")
        os.close(fd)
        try:
            torch.save(payload, tmp)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
        return path


def untrained(
    template_lengths: np.ndarray, net: NetConfig | None = None, seed: int = 0
) -> Checkpoint:
    """A checkpoint of a freshly initialised network (from ``seed``) with an identity
    normaliser and ``template_lengths (17,)``: for timing and for testing the stages around
    the network, whose weights do not matter there."""
    net = net or NetConfig()
    torch.manual_seed(seed)
    slots = (LAYOUT["skeleton_slots"], LAYOUT["per_skeleton"])
    normaliser = Normaliser(
        np.zeros(slots, np.float32),
        np.ones(slots, np.float32),
        np.zeros(LAYOUT["vr_features"], np.float32),
        np.ones(LAYOUT["vr_features"], np.float32),
    )
    weights = LiftingNet(net).state_dict()
    return Checkpoint(net, weights, normaliser, np.asarray(template_lengths), {}, "", 0, [], {})


def load(folder: str | Path) -> Checkpoint:
    """The checkpoint in run folder ``folder`` (or the file itself), checked
    (:mod:`.checkpoint_schema`).

    Raises:
        CheckpointError: no checkpoint, unreadable, holding anything but tensors and plain
            data, another feature layout, or a field that does not match its schema.
    """
    path = Path(folder)
    path = path / FILE if path.is_dir() else path
    if not path.is_file():
        raise CheckpointError(
            f"no ControllerPose checkpoint at {path} (train one: avatarsim train controllerpose)"
        )
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except pickle.UnpicklingError as exc:
        # torch's message advises weights_only=False; only its line naming the object is kept
        lines = str(exc).splitlines()
        reason = next((x for x in lines if "GLOBAL" in x or "Unsupported" in x), type(exc).__name__)
        raise CheckpointError(
            f"{path}: holds Python objects, not only tensors and plain data; a checkpoint is "
            f"data, never code, so it is not loaded ({_one_line(reason)}); retrain with "
            "avatarsim train controllerpose or ask for a checkpoint of this version"
        ) from None
    except Exception as exc:  # torch raises many kinds for a damaged file
        raise CheckpointError(f"{path}: not a readable checkpoint ({_one_line(exc)})") from None
    p = check_payload(payload, path)
    normaliser = {k: v.numpy().astype(np.float32) for k, v in p["normaliser"].items()}
    return Checkpoint(
        p["net"],
        p["best_weights"],
        Normaliser(**normaliser),
        p["template_lengths"].numpy().astype(np.float64),
        p["train"],
        p["manifest_sha256"],
        int(p["epoch"]),
        p["history"],
        p["resume"],
    )


def _one_line(text: object) -> str:
    return " ".join(str(text).split())[:300]

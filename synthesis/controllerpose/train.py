"""Training the lifting network, as ControllerPose §4.3 describes it: Adam, learning rate
1e-3 with a decay of 5e-6 (Keras' ``decay``: ``lr / (1 + decay * step)``), batch 128, MSE on
the joint angles. Beyond the paper: an optional position loss through the FK layer
(``position_weight``), early stopping on the validation split (the paper trains 500 epochs)
and a time budget.

Deterministic on one machine: the weights are initialised from ``seed``, each epoch's order
and dropout draws come from ``(seed, epoch)``, so the same seed gives the same weights, and a
resumed run the weights of an uninterrupted one.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.controllerpose.checkpoint import Checkpoint
from avatarsim.synthesis.controllerpose.examples import Examples
from avatarsim.synthesis.controllerpose.fk import forward_kinematics
from avatarsim.synthesis.controllerpose.network import LiftingNet, NetConfig, check_int, check_real
from avatarsim.synthesis.controllerpose.normaliser import Normaliser

EVAL_CHUNK = 4096


class TrainingDiverged(SynthesisError):
    """The loss went non-finite during training (a learning rate or loss weight too large)."""


@dataclass(frozen=True)
class TrainConfig:
    """How to train (defaults: §4.3 where the paper says, ours where it does not). Checked on
    construction (:class:`~.network.ConfigValueError`): rates and weights finite and not
    negative, the learning rate and time budget positive, counts at least 1 (a batch at
    least 2: batch normalisation; ``max_epochs`` 0: the untrained network)."""

    lr: float = 1e-3
    lr_decay: float = 5e-6
    batch_size: int = 128
    max_epochs: int = 500
    patience: int = 6
    position_weight: float = 0.0
    time_budget_s: float | None = None
    seed: int = 0
    threads: int = 1

    def __post_init__(self) -> None:
        check_real("lr", self.lr, 0.0, strict=True)
        check_real("lr_decay", self.lr_decay, 0.0)
        check_int("batch_size", self.batch_size, 2)
        check_int("max_epochs", self.max_epochs, 0)
        check_int("patience", self.patience, 1)
        check_real("position_weight", self.position_weight, 0.0)
        if self.time_budget_s is not None:
            check_real("time_budget_s", self.time_budget_s, 0.0, strict=True)
        check_int("seed", self.seed, 0)
        check_int("threads", self.threads, 1)

    def as_dict(self) -> dict:
        return asdict(self)


def template_lengths(examples: Examples) -> np.ndarray:
    """``(17,)`` mean bone lengths per metre of standing height."""
    return (examples.lengths / examples.height[:, None]).mean(0)


def tensors(examples: Examples, normaliser: Normaliser) -> dict[str, torch.Tensor]:
    """The examples as the network and the losses read them."""
    features = normaliser.apply(examples.features)
    return {
        "skeletons": torch.from_numpy(features.skeletons),
        "found": torch.from_numpy(features.found),
        "vr": torch.from_numpy(features.vr),
        "angles": torch.from_numpy(examples.angles.astype(np.float32)),
        "lengths": torch.from_numpy(examples.lengths.astype(np.float32)),
        "positions": torch.from_numpy(examples.positions.astype(np.float32)),
    }


def predict(model: LiftingNet, data: dict[str, torch.Tensor]) -> torch.Tensor:
    """``(N, 43)`` angles of ``data`` (eval mode, in chunks, no gradient)."""
    model.eval()
    with torch.no_grad():
        return torch.cat(
            [
                model(
                    data["skeletons"][i : i + EVAL_CHUNK],
                    data["found"][i : i + EVAL_CHUNK],
                    data["vr"][i : i + EVAL_CHUNK],
                )
                for i in range(0, len(data["found"]), EVAL_CHUNK)
            ]
        )


def losses(
    angles: torch.Tensor, data: dict[str, torch.Tensor], position_weight: float
) -> dict[str, torch.Tensor]:
    """``angle_mse`` (rad^2) and, when ``position_weight`` > 0, ``position_mse`` (m^2,
    through FK with the true bone lengths) and their weighted sum ``loss`` for predicted
    ``angles (B, 43)``."""
    angle_mse = nn.functional.mse_loss(angles, data["angles"])
    if position_weight <= 0:
        return {"loss": angle_mse, "angle_mse": angle_mse}
    position_mse = position_error(angles, data)
    return {
        "loss": angle_mse + position_weight * position_mse,
        "angle_mse": angle_mse,
        "position_mse": position_mse,
    }


def position_error(angles: torch.Tensor, data: dict[str, torch.Tensor]) -> torch.Tensor:
    """MSE (m^2) of the keypoints FK places from ``angles (B, 43)`` with the true lengths."""
    positions = forward_kinematics(angles, data["lengths"])
    return nn.functional.mse_loss(positions, data["positions"])


def check_loss(loss: torch.Tensor, where: str) -> None:
    """Raises :class:`TrainingDiverged` when ``loss`` is NaN or infinite: the weights of the
    step that made it are garbage, and every later step would be too."""
    if not bool(torch.isfinite(loss)):
        raise TrainingDiverged(
            f"training diverged: the loss is {float(loss)} at {where}; the checkpoint of the "
            "last finished epoch (if any) is kept. Lower the learning rate or the position "
            "weight"
        )


def batch(data: dict[str, torch.Tensor], index: torch.Tensor) -> dict[str, torch.Tensor]:
    return {k: v[index] for k, v in data.items()}


def train(
    train_set: Examples,
    val_set: Examples,
    net: NetConfig,
    config: TrainConfig,
    manifest_sha256: str = "",
    out: Path | None = None,
    progress: Callable[[dict], None] | None = None,
    resume: Checkpoint | None = None,
) -> Checkpoint:
    """Trains until early stopping, ``max_epochs`` or the time budget; saves the checkpoint
    to ``out`` after every epoch (when given) and returns it. ``resume`` continues a
    checkpoint of the same data and config."""
    torch.set_num_threads(config.threads)
    torch.manual_seed(config.seed)
    model = LiftingNet(net)
    normaliser = Normaliser.fit(train_set.features)
    train_data, val_data = tensors(train_set, normaliser), tensors(val_set, normaliser)
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    schedule = torch.optim.lr_scheduler.LambdaLR(
        optimiser, lambda step: 1.0 / (1.0 + config.lr_decay * step)
    )
    checkpoint = Checkpoint(
        net,
        {k: v.clone() for k, v in model.state_dict().items()},
        normaliser,
        template_lengths(train_set),
        config.as_dict(),
        manifest_sha256,
        0,
        [],
        {"best_val": float("inf"), "bad_epochs": 0, "elapsed_s": 0.0},
    )
    if resume is not None:
        model.load_state_dict(resume.resume["weights"])
        optimiser.load_state_dict(resume.resume["optimiser"])
        schedule.load_state_dict(resume.resume["schedule"])
        checkpoint = resume
        checkpoint.train = config.as_dict()
    n = len(train_set)
    start = time.perf_counter() - checkpoint.resume["elapsed_s"]
    while checkpoint.epoch < config.max_epochs:
        if checkpoint.resume["bad_epochs"] >= config.patience:
            break
        epoch = checkpoint.epoch
        torch.manual_seed(config.seed * 100_003 + epoch)
        order = torch.from_numpy(np.random.default_rng([config.seed, epoch]).permutation(n))
        model.train()
        sums: dict[str, float] = {}
        steps = 0
        # A last batch of one cannot be batch-normalised; it waits for the next epoch.
        for i in range(0, n - 1, config.batch_size):
            data = batch(train_data, order[i : i + config.batch_size])
            if len(data["found"]) < 2:
                continue
            out_angles = model(data["skeletons"], data["found"], data["vr"])
            terms = losses(out_angles, data, config.position_weight)
            check_loss(terms["loss"], f"epoch {epoch + 1}, batch {steps + 1}")
            optimiser.zero_grad()
            terms["loss"].backward()
            optimiser.step()
            schedule.step()
            for k, v in terms.items():
                sums[k] = sums.get(k, 0.0) + float(v.detach())
            steps += 1
        val_angles = predict(model, val_data)
        val_terms = losses(val_angles, val_data, config.position_weight)
        val_terms["position_mse"] = position_error(val_angles, val_data)
        check_loss(val_terms["loss"], f"epoch {epoch + 1}, validation")
        val_loss = float(val_terms["loss"])
        elapsed = time.perf_counter() - start
        record = {
            "epoch": epoch + 1,
            **{f"train_{k}": v / max(steps, 1) for k, v in sums.items()},
            **{f"val_{k}": float(v) for k, v in val_terms.items()},
            "elapsed_s": elapsed,
        }
        checkpoint.history.append(record)
        state = checkpoint.resume
        if val_loss < state["best_val"]:
            state["best_val"], state["bad_epochs"] = val_loss, 0
            checkpoint.best_weights = {k: v.clone() for k, v in model.state_dict().items()}
        else:
            state["bad_epochs"] += 1
        state.update(
            weights=model.state_dict(),
            optimiser=optimiser.state_dict(),
            schedule=schedule.state_dict(),
            elapsed_s=elapsed,
        )
        checkpoint.epoch = epoch + 1
        if out is not None:
            checkpoint.save(out)
        if progress is not None:
            progress(record)
        if config.time_budget_s is not None and elapsed >= config.time_budget_s:
            break
    return checkpoint

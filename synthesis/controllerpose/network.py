"""The lifting network (ControllerPose §4.3, Fig. 6I): a multi-input MLP with batch
normalisation, ReLU, dropout and residual connections; 43 joint angles out.

Inputs (:mod:`.features`): ``skeletons (B, 4, 289)``, ``found (B, 4)`` and ``vr (B, 15)``.
Each skeleton slot has its own input branch (Linear, BatchNorm, ReLU); a slot without a
skeleton contributes zeros and its ``found`` flag enters the trunk, so a missing skeleton
is masked rather than read as a skeleton of zeros. The VR features have their own branch,
left out for the paper's ablation without VR data (§5.3, ``use_vr=False``). The branches are
concatenated into a trunk of residual blocks (Linear, BatchNorm, ReLU, Dropout, twice, plus
the skip) and a linear head. Widths and depth are not in the paper; :class:`NetConfig`
holds ours.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from numbers import Integral, Real

import torch
from torch import nn

from avatarsim.avatar_models.body17_angles import N_DOF
from avatarsim.synthesis.base import SynthesisError
from avatarsim.synthesis.controllerpose.features import PER_SKELETON, SKELETON_SLOTS, VR_FEATURES


class ConfigValueError(SynthesisError):
    """A network or training config value of the wrong type or out of its range; ``field``
    names it (the CLI maps it to its option)."""

    def __init__(self, field: str, reason: str) -> None:
        self.field, self.reason = field, reason
        super().__init__(f"{field} {reason}")


def check_int(field: str, value: object, minimum: int) -> None:
    """``value`` is an integer (not a bool) of at least ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise ConfigValueError(field, f"must be an integer, got {value!r}")
    if value < minimum:
        raise ConfigValueError(field, f"must be at least {minimum}, got {value}")


def check_real(
    field: str, value: object, minimum: float, below: float = math.inf, strict: bool = False
) -> None:
    """``value`` is a finite number in ``[minimum, below)`` (``(minimum, below)`` when
    ``strict``): NaN and infinities are refused."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise ConfigValueError(field, f"must be a number, got {value!r}")
    low_ok = value > minimum if strict else value >= minimum
    if not (math.isfinite(value) and low_ok and value < below):
        low = f"more than {minimum:g}" if strict else f"at least {minimum:g}"
        high = "" if below == math.inf else f" and below {below:g}"
        raise ConfigValueError(field, f"must be a finite number {low}{high}, got {value}")


@dataclass(frozen=True)
class NetConfig:
    """Sizes of :class:`LiftingNet` (ours; the paper gives none). Checked on construction
    (:class:`ConfigValueError`): widths at least 1, blocks at least 0, dropout in [0, 1),
    ``use_vr`` a bool."""

    branch_width: int = 64
    width: int = 256
    blocks: int = 2
    dropout: float = 0.1
    use_vr: bool = True

    def __post_init__(self) -> None:
        check_int("branch_width", self.branch_width, 1)
        check_int("width", self.width, 1)
        check_int("blocks", self.blocks, 0)
        check_real("dropout", self.dropout, 0.0, 1.0)
        if not isinstance(self.use_vr, bool):
            raise ConfigValueError("use_vr", f"must be true or false, got {self.use_vr!r}")

    def as_dict(self) -> dict:
        return asdict(self)

    def state_size(self) -> int:
        """Numbers in the network's state dict (parameters and batch-norm statistics),
        counted from the sizes without building it: a dense layer ``a -> b`` holds
        ``a*b + b`` linear and ``4b + 1`` batch-norm numbers."""

        def dense_size(n_in: int, n_out: int) -> int:
            return n_in * n_out + n_out + 4 * n_out + 1

        w = self.branch_width
        n_joined = w * (SKELETON_SLOTS + self.use_vr) + SKELETON_SLOTS
        return (
            SKELETON_SLOTS * dense_size(PER_SKELETON, w)
            + self.use_vr * dense_size(VR_FEATURES, w)
            + dense_size(n_joined, self.width)
            + self.blocks * 2 * dense_size(self.width, self.width)
            + self.width * N_DOF
            + N_DOF
        )

    def training_bytes(self, batch_size: int) -> int:
        """A lower estimate of the memory training needs: five float32 copies of the state
        (weights, gradients, Adam's two moments, the best weights) and, per example of a
        batch, the trunk's activations (four per dense layer: linear, batch norm, ReLU,
        dropout) kept for the backward pass and their gradients."""
        dense_layers = 1 + 2 * self.blocks
        activations = batch_size * self.width * 4 * dense_layers * 2
        return 4 * (5 * self.state_size() + activations)


def dense(n_in: int, n_out: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(n_in, n_out), nn.BatchNorm1d(n_out), nn.ReLU())


class ResidualBlock(nn.Module):
    """``x + f(x)``, ``f`` two (Linear, BatchNorm, ReLU, Dropout) layers."""

    def __init__(self, width: int, dropout: float) -> None:
        super().__init__()
        self.body = nn.Sequential(
            dense(width, width), nn.Dropout(dropout), dense(width, width), nn.Dropout(dropout)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.body(x)


class LiftingNet(nn.Module):
    """Features -> ``(B, 43)`` joint angles (module docstring)."""

    def __init__(self, config: NetConfig) -> None:
        super().__init__()
        self.config = config
        w = config.branch_width
        self.skeleton_branches = nn.ModuleList(
            dense(PER_SKELETON, w) for _ in range(SKELETON_SLOTS)
        )
        self.vr_branch = dense(VR_FEATURES, w) if config.use_vr else None
        n_joined = w * (SKELETON_SLOTS + config.use_vr) + SKELETON_SLOTS
        self.trunk = nn.Sequential(
            dense(n_joined, config.width),
            nn.Dropout(config.dropout),
            *(ResidualBlock(config.width, config.dropout) for _ in range(config.blocks)),
        )
        self.head = nn.Linear(config.width, N_DOF)

    def forward(
        self, skeletons: torch.Tensor, found: torch.Tensor, vr: torch.Tensor
    ) -> torch.Tensor:
        mask = found.to(skeletons.dtype)
        parts = [
            branch(skeletons[:, s]) * mask[:, s, None]
            for s, branch in enumerate(self.skeleton_branches)
        ]
        if self.vr_branch is not None:
            parts.append(self.vr_branch(vr))
        parts.append(mask)
        return self.head(self.trunk(torch.cat(parts, -1)))

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

from dataclasses import asdict, dataclass

import torch
from torch import nn

from avatar_models.body17_angles import N_DOF
from synthesis.controllerpose.features import PER_SKELETON, SKELETON_SLOTS, VR_FEATURES


@dataclass(frozen=True)
class NetConfig:
    """Sizes of :class:`LiftingNet` (ours; the paper gives none)."""

    branch_width: int = 64
    width: int = 256
    blocks: int = 2
    dropout: float = 0.1
    use_vr: bool = True

    def as_dict(self) -> dict:
        return asdict(self)


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

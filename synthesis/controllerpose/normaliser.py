"""The feature normaliser fitted on the training examples (z-scores, stored in the
checkpoint): found skeleton slots and VR features to zero mean, unit deviation; slots
without a skeleton stay 0 (masked)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.synthesis.controllerpose.features import Features

MIN_STD = 1e-3  # a feature constant in training (e.g. an always-missing pair) is not scaled up


@dataclass(frozen=True)
class Normaliser:
    """``skeleton_mean/std (4, 289)``, ``vr_mean/std (15,)``, float32."""

    skeleton_mean: np.ndarray
    skeleton_std: np.ndarray
    vr_mean: np.ndarray
    vr_std: np.ndarray

    @classmethod
    def fit(cls, features: Features) -> Normaliser:
        found = features.found[..., None]
        count = np.maximum(found.sum(0), 1)
        mean = (features.skeletons * found).sum(0) / count
        var = (((features.skeletons - mean) * found) ** 2).sum(0) / count
        return cls(
            mean.astype(np.float32),
            np.maximum(np.sqrt(var), MIN_STD).astype(np.float32),
            features.vr.mean(0).astype(np.float32),
            np.maximum(features.vr.std(0), MIN_STD).astype(np.float32),
        )

    def apply(self, features: Features) -> Features:
        skeletons = (features.skeletons - self.skeleton_mean) / self.skeleton_std
        return Features(
            np.where(features.found[..., None], skeletons, 0.0).astype(np.float32),
            features.found,
            ((features.vr - self.vr_mean) / self.vr_std).astype(np.float32),
        )

    def state(self) -> dict[str, np.ndarray]:
        return dict(self.__dict__)

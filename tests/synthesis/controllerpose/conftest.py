"""Small ControllerPose examples for the package's tests: keypoint features of random
detections, VR features of random device poses, targets of a generated motion."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body17_angles import angles_from_positions
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.synthesis.controllerpose.examples import Examples
from avatarsim.synthesis.controllerpose.features import Features, skeleton_features, vr_features
from avatarsim.synthesis.controllerpose.network import NetConfig

TINY_NET = NetConfig(branch_width=16, width=64, blocks=1, dropout=0.0)


def make_examples(n: int, seed: int) -> Examples:
    rng = np.random.default_rng(seed)
    uv = rng.uniform(0, 640, (n, 4, 17, 2))
    conf = rng.uniform(0.2, 1.0, (n, 4, 17)) * (rng.random((n, 4, 17)) > 0.1)
    skeletons, found = skeleton_features(uv, conf)
    head_quat = quat.normalize(rng.normal(size=(n, 4)))
    hand_quat = quat.normalize(rng.normal(size=(n, 2, 4)))
    vr = vr_features(rng.normal(size=(n, 3)), head_quat, rng.normal(size=(n, 2, 3)), hand_quat)
    positions = body17_positions(generate("box", duration_s=n / 30.0 + 0.1, fps=30.0, seed=seed))[
        :n
    ]
    angles, lengths = angles_from_positions(positions)
    centred = positions - positions[:, 2:3]
    return Examples(
        Features(skeletons, found, vr),
        angles.astype(np.float32),
        lengths.astype(np.float32),
        centred.astype(np.float32),
        np.full(n, 1.75, dtype=np.float32),
        np.zeros(n, dtype=np.int64),
        np.arange(n) / 30.0,
    )


@pytest.fixture(scope="session")
def tiny_examples() -> Examples:
    return make_examples(64, seed=0)

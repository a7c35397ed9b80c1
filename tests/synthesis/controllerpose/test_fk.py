"""The torch FK layer equals avatar_models' numpy FK (the labels' kinematics) to 1e-6 m."""

from __future__ import annotations

import numpy as np
import torch

from avatarsim.avatar_models.body17_angles import angles_from_positions, positions_from_angles
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.synthesis.controllerpose.fk import forward_kinematics


def test_torch_fk_equals_numpy_fk_on_random_and_real_angles():
    rng = np.random.default_rng(0)
    random_angles = rng.normal(scale=1.5, size=(200, 43))
    random_angles[0] = 0.0  # the rest pose: Rodrigues' small-angle branch
    motion_angles, motion_lengths = angles_from_positions(
        body17_positions(generate("dribble", duration_s=1.0, fps=30.0, seed=1))
    )
    angles = np.concatenate([random_angles, motion_angles])
    lengths = np.concatenate([rng.uniform(0.05, 0.5, (200, 17)), motion_lengths])
    expected = positions_from_angles(angles, lengths)
    got = forward_kinematics(torch.from_numpy(angles), torch.from_numpy(lengths)).numpy()
    assert np.abs(got - expected).max() < 1e-6
    got32 = forward_kinematics(
        torch.from_numpy(angles).float(), torch.from_numpy(lengths).float()
    ).numpy()
    assert np.abs(got32 - expected).max() < 1e-5  # float32 training precision


def test_gradient_is_finite_at_the_rest_pose():
    angles = torch.zeros(3, 43, dtype=torch.float64, requires_grad=True)
    forward_kinematics(angles, torch.full((17,), 0.3, dtype=torch.float64)).sum().backward()
    assert torch.isfinite(angles.grad).all()

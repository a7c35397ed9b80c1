"""The 43-DoF body17 parameterisation: its size, its rest pose, and the exact round trip
positions -> angles -> positions on generated motion."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.body17_angles import (
    DOF_SLICES,
    HINGES,
    N_DOF,
    angles_from_positions,
    positions_from_angles,
)
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions


def test_43_dof_13_ball_joints_and_4_hinges():
    widths = [s.stop - s.start for s in DOF_SLICES]
    assert N_DOF == 43 and len(widths) == 17
    assert sorted(widths).count(1) == 4 and sorted(widths).count(3) == 13
    assert {INDEX[n] for n in ("l_wrist", "r_wrist", "l_ankle", "r_ankle")} == set(HINGES)


def test_zero_angles_stand_facing_x_with_limbs_hanging():
    lengths = np.full(17, 0.3)
    p = positions_from_angles(np.zeros(43), lengths)
    assert np.allclose(p[INDEX["pelvis"]], 0.0)
    assert np.allclose(p[INDEX["head"]], [0, 0, 0.6])  # spine and neck straight up
    assert p[INDEX["l_hip"], 1] > 0 > p[INDEX["r_hip"], 1]  # left is +Y
    assert np.allclose(p[INDEX["l_wrist"]] - p[INDEX["l_shoulder"]], [0, 0, -0.6])
    assert np.allclose(p[INDEX["l_foot"]] - p[INDEX["l_ankle"]], [0.3, 0, 0])  # toes to +X


def test_round_trip_is_exact_on_generated_motion():
    for activity in ("walk", "kick", "box"):
        positions = body17_positions(generate(activity, duration_s=1.0, fps=30.0, seed=3))
        angles, lengths = angles_from_positions(positions)
        assert angles.shape == (len(positions), 43) and np.isfinite(angles).all()
        back = positions_from_angles(angles, lengths)
        centred = positions - positions[:, INDEX["pelvis"] : INDEX["pelvis"] + 1]
        assert np.abs(back - centred).max() < 1e-9


def test_elbow_flexion_is_the_hinge_angle():
    """A right angle at the elbow, forearm forward: the wrist's hinge DoF is -pi/2 (the
    forearm turns from -Z to +X about y), whatever the body's heading."""
    lengths = np.full(17, 0.3)
    angles = np.zeros(43)
    angles[DOF_SLICES[INDEX["l_wrist"]]] = -np.pi / 2
    p = positions_from_angles(angles, lengths)
    assert np.allclose(p[INDEX["l_wrist"]] - p[INDEX["l_elbow"]], [0.3, 0, 0])
    turned = p @ np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]).T  # 90 deg about z
    recovered, _ = angles_from_positions(turned)
    assert np.isclose(recovered[DOF_SLICES[INDEX["l_wrist"]]][0], -np.pi / 2)

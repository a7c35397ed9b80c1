"""Hand-location study: analytic poses, then the built-in library next to the paper."""

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.generator import generate_library
from avatarsim.render_cams.hand_location import hand_location_study, hand_measures


def test_analytic_hand_positions():
    joints = np.zeros((1, 17, 3))
    joints[0, INDEX["pelvis"]] = [0.0, 0.0, 1.0]
    joints[0, INDEX["neck"]] = [0.0, 0.0, 1.5]
    joints[0, INDEX["l_shoulder"]] = [0.0, 0.2, 1.45]  # facing +X, left is +Y
    joints[0, INDEX["r_shoulder"]] = [0.0, -0.2, 1.45]
    joints[0, INDEX["l_wrist"]] = [0.43, 0.0, 1.3]  # reaching forward
    joints[0, INDEX["r_wrist"]] = [0.05, -0.3, 0.9]  # by the side, below the pelvis
    front, dist = hand_measures(joints)
    assert front[0].tolist() == [True, False]
    assert dist[0] == pytest.approx([0.43, np.sqrt(0.05**2 + 0.3**2 + 0.1**2)])


def test_builtin_library_study():
    motions = generate_library(("wave", "box", "walk"), n_subjects=2, duration_s=2.0, fps=30)
    result = hand_location_study(motions)
    assert result["motions"] == 6
    assert 0.0 <= result["in_front_share"] <= 1.0
    assert 10.0 < result["camera_to_body_cm"] < 80.0
    assert np.isclose(result["paper_in_front_share"], 0.683)

"""Hands on the controllers: the palm point is the devices' grip, the handle under it; an
avatar with short arms cannot reach a raised controller and gets it attached to the hand."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.generator.subject import Subject
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.vr import nominal_attachment
from avatarsim.synthesis.avatargo.hands import (
    CONTROLLER_RADIUS_M,
    beyond_reach,
    grip_of,
    out_of_reach,
)
from avatarsim.synthesis.avatargo.study import SimulatedUser, study_run
from avatarsim.synthesis.avatargo.walk_in import t_pose


def test_grip_holds_the_handle_under_the_palm():
    skeleton = load_rig("avatar").skeleton
    grip = grip_of(skeleton)
    np.testing.assert_allclose(
        grip.palm[0], nominal_attachment("left_controller", skeleton).position
    )
    below = (grip.handle.mean(1) - grip.palm)[:, 2]  # the palms face down at rest
    assert (below < -CONTROLLER_RADIUS_M).all()


def test_out_of_reach():
    shoulders = np.zeros((1, 2, 3))
    goals = np.array([[[0.5, 0.0, 0.0], [0.0, 0.7, 0.0]]])
    assert out_of_reach(shoulders, goals, np.array([0.6, 0.6])).tolist() == [[False, True]]
    # The same from the distances (0.5 m and 0.7 m from the shoulders).
    assert beyond_reach(np.array([[0.5, 0.7]]), np.array([0.6, 0.6])).tolist() == [[False, True]]


def test_short_arms_attach_the_controller():
    """Avatar arms 10 % short, a user holding the T-pose (arms straight out): the controllers
    are out of reach (the virtual controller is then in the hand, off the tracked one); the
    same user with the avatar's arms as long as theirs reaches them."""
    truth = t_pose(generate("wave", Subject(), 0.1, 90.0, 0), 0.0, 0.5)
    short = study_run(truth, SimulatedUser(0, 1.0, 0.9, 0.0), fingers=False)["exact"]
    same = study_run(truth, SimulatedUser(0, 1.0, 1.0, 0.0), fingers=False)["exact"]
    assert short["unreached_frac"] > 0.0 and same["unreached_frac"] == 0.0
    assert short["palm_cm"] > same["palm_cm"]

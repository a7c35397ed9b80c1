"""NotTracked joints hold, Inferred ones blend halfway to the last Tracked rotation, joints
never seen stay at rest; the rules carry across calls."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.render_cams.kinect import TrackingState
from avatarsim.synthesis.movebox.confidence import ConfidenceFilter, bone_states

T, I, N = TrackingState.TRACKED, TrackingState.INFERRED, TrackingState.NOT_TRACKED
Z = np.array([0.0, 0.0, 1.0])


def about_z(deg) -> np.ndarray:
    return quat.from_axis_angle(Z, np.deg2rad(np.asarray(deg, float)))[:, None]


def test_hold_blend_and_fallback():
    local = about_z([10, 20, 30, 40, 50])
    states = np.array([[N], [T], [I], [N], [T]])
    out = ConfidenceFilter.at_rest(1)(local, states)
    angles = np.rad2deg(2 * np.arctan2(out[:, 0, 3], out[:, 0, 0]))
    # never seen -> rest; tracked; inferred halfway between 20 and 30; held; tracked
    assert np.allclose(angles, [0, 20, 25, 25, 50], atol=1e-6)


def test_rules_carry_across_calls():
    local = about_z([10, 20, 30, 40, 50, 60])
    states = np.array([[T], [N], [I], [N], [T], [I]])
    whole = ConfidenceFilter.at_rest(1)(local, states)
    split = ConfidenceFilter.at_rest(1)
    parts = np.concatenate([split(local[:2], states[:2]), split(local[2:], states[2:])])
    assert np.allclose(whole, parts)


def test_bone_state_is_the_worst_of_its_joints():
    states = np.array([[T, I, N], [T, T, I]])
    got = bone_states(states, [(), (0, 1), (1, 2)])
    assert got.tolist() == [[T, I, N], [T, T, I]]

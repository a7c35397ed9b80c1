"""The one foot-contact labeller: heights and speeds to contact labels."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.foot_contact import contact_mask, horizontal_speed, lasting


def test_low_slow_points_are_in_contact():
    height = np.array([[0.00, 0.20], [0.04, 0.02], [0.06, 0.00]])
    vz = np.array([[0.0, -1.0], [0.5, 0.1], [0.0, 0.0]])
    vxy = np.array([[3.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
    only_height = contact_mask(height, 0.05)
    assert only_height.tolist() == [[True, False], [True, True], [False, True]]
    labelled = contact_mask(
        height,
        0.05,
        vertical_velocity=vz,
        max_vertical_speed=0.3,
        horizontal_speed=vxy,
        max_horizontal_speed=2.5,
    )
    # frame 0 left slides too fast, frame 1 left falls too fast: both swing.
    assert labelled.tolist() == [[False, False], [False, True], [False, True]]


def test_floor_level_is_subtracted_per_foot():
    height = np.array([[1.00, 0.50], [1.10, 0.52]])
    assert contact_mask(height, 0.05, floor=np.array([1.0, 0.5])).tolist() == [
        [True, True],
        [False, True],
    ]


def test_short_contacts_are_dropped_longer_ones_kept_whole():
    contact = np.array([0, 1, 1, 0, 1, 1, 1, 1, 0, 1], bool)[:, None]
    kept = lasting(contact, 3)[:, 0]
    assert kept.tolist() == [False] * 4 + [True] * 4 + [False] * 2
    assert lasting(contact, 1) is contact


def test_horizontal_speed_ignores_vertical_motion():
    t = np.arange(10) / 10.0
    positions = np.stack([3.0 * t, 4.0 * t, 5.0 * t], axis=-1)[:, None]  # (T, 1, 3)
    np.testing.assert_allclose(horizontal_speed(positions, 10.0), 5.0)

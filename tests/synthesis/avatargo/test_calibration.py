"""Walk-in calibration: roles from the T-pose plane, whatever the device order and strap
rotations; typed errors for a missing tracker, a non-T-pose and unrecognisable trackers."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import Motion, quat
from avatarsim.avatar_models.generator import sample_subject
from avatarsim.avatar_models.generator.subject import subject_skeleton
from avatarsim.render_cams.vr import FULL_BODY, VRSetup
from avatarsim.synthesis.avatargo.calibration import (
    MissingDeviceError,
    NotTPoseError,
    SwappedTrackersError,
    classes_of,
    identify_roles,
)
from avatarsim.synthesis.avatargo.study import sample_user, setup_for
from avatarsim.synthesis.avatargo.walk_in import t_pose, walk_in


def _sample(seed: int = 0):
    """A random user's walk-in sample: straps up to 5 cm off and turned at random."""
    motion = _still(seed)
    user = sample_user(seed, motion.skeleton)
    return walk_in(setup_for(user), motion, user.seed, user.heading_rad), user


def _still(seed: int) -> Motion:
    """One frame of a random subject in its rest pose (a T-pose: the walk-in stands in it)."""
    skeleton = subject_skeleton(sample_subject(np.random.default_rng(seed)))
    rest = np.tile(quat.IDENTITY, (1, skeleton.n_joints, 1))
    return Motion(skeleton, 90.0, np.zeros((1, 3)), rest)


@pytest.mark.parametrize("seed", range(3))
def test_roles_for_every_device_order(seed):
    """All 720 orders of the six devices give each device its own role back, for users facing
    random headings with randomly strapped and turned trackers."""
    frame, user = _sample(seed)
    classes = classes_of(frame.device_names)
    for order in itertools.permutations(range(6)):
        order = np.array(order)
        roles = identify_roles(
            frame.positions[order], frame.quaternions[order], tuple(classes[i] for i in order)
        )
        assert [frame.device_names[order[i]] for i in roles.index] == list(FULL_BODY)
    facing = np.array([np.cos(user.heading_rad), np.sin(user.heading_rad), 0.0])
    assert roles.facing @ facing > np.cos(np.radians(5.0))


def test_roles_ignore_tracker_rotations():
    """Any rotation of the three trackers (100 draws) leaves the roles alone."""
    frame, _ = _sample(1)
    classes = classes_of(frame.device_names)
    rng = np.random.default_rng(7)
    trackers = [FULL_BODY.index(d) for d in FULL_BODY if d.endswith("tracker")]
    for _ in range(100):
        q = frame.quaternions.copy()
        q[trackers] = quat.from_scipy(Rotation.random(3, random_state=rng))
        roles = identify_roles(frame.positions, q, classes)
        assert list(roles.index) == list(range(6))


def test_missing_tracker_is_named():
    frame, _ = _sample(0)
    keep = [i for i, d in enumerate(frame.device_names) if d != "back_tracker"]
    names = tuple(frame.device_names[i] for i in keep)
    with pytest.raises(MissingDeviceError, match="3 tracked tracker.*found 2"):
        identify_roles(frame.positions[keep], frame.quaternions[keep], classes_of(names))
    lost = frame.positions.copy()
    lost[FULL_BODY.index("left_foot_tracker")] = np.nan  # listed but not tracked
    with pytest.raises(MissingDeviceError, match="1 not tracked"):
        identify_roles(lost, frame.quaternions, classes_of(frame.device_names))


def test_arms_down_is_not_a_t_pose():
    """Hands lowered to the hips: not a T-pose, and the message says what to do."""
    stream = VRSetup(devices=FULL_BODY).sample(t_pose(_still(0), 0.0), seed=0)
    positions = stream.positions[0].copy()
    hands = [FULL_BODY.index("left_controller"), FULL_BODY.index("right_controller")]
    positions[hands, 1] *= 0.2  # hands at the hips' width
    positions[hands, 2] = 0.9
    with pytest.raises(NotTPoseError, match="spread your arms"):
        identify_roles(positions, stream.quaternions[0], classes_of(stream.device_names))


def test_trackers_at_one_height_cannot_be_told_apart():
    frame, _ = _sample(0)
    positions = frame.positions.copy()
    back = FULL_BODY.index("back_tracker")
    positions[back, 2] = positions[FULL_BODY.index("left_foot_tracker"), 2] + 0.05
    with pytest.raises(SwappedTrackersError, match="lower back"):
        identify_roles(positions, frame.quaternions, classes_of(frame.device_names))

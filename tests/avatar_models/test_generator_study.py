"""The ControllerPose study activity (§5.1, Figures 7-8): twenty lower-body poses, eight with
a leg lifted and dropped down to regain balance; one controller at a time sweeping the 16
spheres of a 69 x 51 x 22 cm volume at about 1.1 m/s."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.sim.plausibility import check_motion

ACTIVITY = "controllerpose_study"
FPS = 30.0
WRISTS = [INDEX["l_wrist"], INDEX["r_wrist"]]
ANKLES = [INDEX["l_ankle"], INDEX["r_ankle"]]


@pytest.fixture(scope="module")
def poses() -> dict[str, int]:
    """The first seed of each study pose."""
    seeds: dict[str, int] = {}
    for seed in range(300):
        motion = generate(ACTIVITY, duration_s=0.05, fps=FPS, seed=seed)
        seeds.setdefault(motion.meta["study_pose"], seed)
    return seeds


@pytest.fixture(scope="module")
def sweep():
    """16 s (every sphere group once) of a 1.75 m subject, and its body17 joints."""
    motion = generate(ACTIVITY, Subject(height_m=1.75), duration_s=16.0, fps=FPS, seed=0)
    return motion, body17_positions(motion)


def test_twenty_poses_eight_lift_a_leg_and_drop_it_to_regain_balance(poses):
    assert len(poses) == 20
    lifting = []
    for name, seed in poses.items():
        motion = generate(ACTIVITY, duration_s=8.0, fps=FPS, seed=seed)
        ankles = body17_positions(motion)[:, ANKLES, 2]  # (T, 2)
        raised = ankles - ankles.min(axis=0) > 0.05  # 5 cm above its lowest
        if raised.any():
            side = int(np.argmax(raised.mean(axis=0)))
            up = raised[:, side]
            assert not raised[:, 1 - side].any(), name  # one leg at a time
            assert 0.4 < up.mean() < 0.95, name  # mostly up ...
            assert np.count_nonzero(np.diff(up.astype(int)) == -1) >= 1, name  # ... dropped
            lifting.append(name)
    assert len(lifting) == 8, lifting


def test_arms_sweep_the_sixteen_spheres_of_the_study_volume(sweep):
    motion, joints = sweep
    root = motion.root_pos
    wrists = joints[:, WRISTS] - root[:, None]  # the spheres are locked to the body
    speed = np.linalg.norm(np.gradient(joints[:, WRISTS], 1.0 / FPS, axis=0), axis=-1)
    shoulder = joints[:, INDEX["l_shoulder"], 2] - root[:, 2]
    # Pauses at spheres (not at rest by the thigh): where the hand stops in front of the body.
    at_sphere = (speed < 0.03) & (wrists[..., 2] > shoulder[:, None] - 0.35)
    points = wrists[at_sphere]
    extent_cm = 100 * (points.max(axis=0) - points.min(axis=0))
    np.testing.assert_allclose(extent_cm, [22.0, 69.0, 51.0], atol=1.0)  # depth, width, height
    spheres: list[np.ndarray] = []  # stops more than 3 cm from every earlier one
    for p in points:
        if all(np.linalg.norm(p - q) > 0.03 for q in spheres):
            spheres.append(p)
    assert len(spheres) == 16
    # One controller at a time, moving at about 1.1 m/s between spheres.
    assert not np.any((speed > 0.1).all(axis=1))
    assert np.mean(speed[speed > 0.05]) == pytest.approx(1.1, abs=0.15)  # measured 1.07-1.10


def test_every_study_pose_is_physically_plausible(poses):
    for name, seed in poses.items():
        report = check_motion(generate(ACTIVITY, duration_s=3.0, seed=seed))
        assert not report.failed_checks, (name, report.failed_checks)

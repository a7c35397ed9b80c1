"""The generator's clips pass the physics checks (:func:`sim.plausibility.check_motion`).

Every activity on the ground passes every check with the default thresholds; climbing a
ladder and swimming pass everything but floating and residual force (the scene has no ladder
and no water to hold the body up).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import ACTIVITIES, Subject, generate, sample_subject
from avatarsim.avatar_models.generator.com import MassModel, lipm_centre_of_mass
from avatarsim.sim.plausibility import check_motion

# The tall, fast walker swings its legs hardest; the small tired boxer turns its arm furthest.
SUBJECTS = (
    Subject(),
    Subject(height_m=1.93, style="energetic", leg_factor=1.05),
    sample_subject(np.random.default_rng(3)),
)
UNSUPPORTED = {"climb_ladder", "swim"}  # no ladder or water in the physics scene
EXPECTED_FAILURES = {"floating", "residual_force"}


@pytest.mark.parametrize(
    ("activity", "i"),
    [(a, i) for a in ACTIVITIES for i in range(len(SUBJECTS))],
)
def test_generated_activity_is_physically_plausible(activity, i):
    report = check_motion(generate(activity, SUBJECTS[i], duration_s=2.5, seed=i))
    allowed = EXPECTED_FAILURES if activity in UNSUPPORTED else set()
    unexpected = set(report.failed_checks) - allowed
    assert not unexpected, (activity, i, report.failed_checks, report.contract()["details"])


def _mujoco_centre_of_mass(motion) -> np.ndarray:
    """``(T, 3)`` whole-body centre of mass, from MuJoCo's model of the body."""
    body = build_body(motion.skeleton)
    model = body.model
    data = mujoco.MjData(model)
    com = []
    for qpos in body.qpos_from_motion(motion):
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        com.append(data.subtree_com[0].copy())
    return np.array(com)


def test_vertical_motion_is_smooth_in_walking_and_running():
    """Vertical acceleration (second differences, no filtering) within the human range: the
    walking pelvis about +-0.3 g (vaulting); the running body's centre of mass at most -1 g
    (free fall; its pelvis drops faster while the legs fold under it)."""
    for activity, lowest_g in (("walk", -0.4), ("run", -1.05)):
        for i, subject in enumerate(SUBJECTS):
            motion = generate(activity, subject, duration_s=3.0, seed=i)
            z = _mujoco_centre_of_mass(motion)[:, 2] if activity == "run" else motion.root_pos[:, 2]
            accel_g = np.diff(z, 2) * motion.fps**2 / 9.81
            assert accel_g.min() > lowest_g, (activity, i, accel_g.min())
            assert accel_g.max() < 3.0, (activity, i, accel_g.max())


def test_planned_centre_of_mass_is_the_physics_bodys():
    motion = generate("run", SUBJECTS[1], duration_s=0.5, seed=0)
    planned = MassModel.of(motion.skeleton).centre_of_mass(motion)
    np.testing.assert_allclose(planned, _mujoco_centre_of_mass(motion), atol=1e-6)


def test_pendulum_centre_of_mass_solves_the_zmp_equation():
    """``c - c'' / omega^2 = p`` (second differences) for a step-like ZMP, and a constant ZMP
    gives a centre of mass standing still over it."""
    fps, height = 60.0, 0.9
    zmp = np.zeros((120, 2))
    zmp[40:80] = [0.6, -0.1]
    zmp[80:] = [1.2, 0.1]
    com = lipm_centre_of_mass(zmp, height, fps)
    recovered = com[1:-1] - np.diff(com, 2, axis=0) * fps**2 * height / 9.81
    np.testing.assert_allclose(recovered, zmp[1:-1], atol=1e-9)
    assert np.all(np.diff(com[:, 0]) >= 0)  # bounded: no overshoot from the solution
    np.testing.assert_allclose(lipm_centre_of_mass(np.full((30, 2), 0.3), height, fps), 0.3)


@pytest.mark.parametrize("i", range(len(SUBJECTS)))
def test_walking_zero_moment_point_stays_under_the_stance_foot(i):
    """The zero-moment point of the walk's centre of mass (MuJoCo's, second differences,
    linear inverted pendulum at its mean height) lies between heel and toes of the only
    standing foot, within the foot's width of its ankle: the floor can hold it."""
    motion = generate("walk", SUBJECTS[i], duration_s=3.0, fps=60.0, seed=i)
    com = _mujoco_centre_of_mass(motion)
    accel = np.zeros_like(com)
    accel[1:-1] = np.diff(com, 2, axis=0) * motion.fps**2
    zmp = com[:, :2] - accel[:, :2] * com[:, 2:].mean() / 9.81
    pos, _ = motion.fk()
    skel = motion.skeleton
    contacts = motion.meta["planned_contacts"]
    for side, other in (("L", 1), ("R", 0)):
        ankle = pos[:, skel.index(f"Bip01 {side} Foot"), :2]
        heel = pos[:, skel.index(f"Bip01 {side} Heel"), 0]
        toe = pos[:, skel.index(f"Bip01 {side} Toe0Nub"), 0]
        alone = contacts[:, 1 - other] & ~contacts[:, other]
        alone[:3] = alone[-3:] = False
        assert alone.sum() > 30
        assert np.all(zmp[alone, 0] > heel[alone] - 0.02), side
        assert np.all(zmp[alone, 0] < toe[alone] + 0.02), side
        assert np.all(np.abs(zmp[alone, 1] - ankle[alone, 1]) < 0.05), side

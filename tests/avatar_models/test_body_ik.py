"""Humanoid IK with mink: known poses are recovered, joint limits hold, bad input is refused."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body import BodyError, build_body
from avatarsim.avatar_models.body.ik import HumanoidIK, humanoid_model, motion_from_qpos
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import body17_positions, load_rig


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


@pytest.fixture(scope="module")
def ik(body):
    return HumanoidIK(humanoid_model(body), BODY17)


@pytest.fixture(scope="module")
def walk_qpos(body):
    return body.qpos_from_motion(generate("walk", duration_s=1.0, fps=30.0))


def _hinge_angle(positions, a, b, c):
    """Angle at body17 joint ``b`` between the bones to ``a`` and ``c`` (radians)."""
    i = [BODY17.index(n) for n in (a, b, c)]
    u, v = (
        positions[..., i[0], :] - positions[..., i[1], :],
        positions[..., i[2], :] - positions[..., i[1], :],
    )
    cos = np.sum(u * v, -1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.arccos(np.clip(cos, -1, 1))


def test_recovers_known_walk_pose(ik, walk_qpos):
    targets = np.stack([ik.frame_positions(q) for q in walk_qpos])
    result = ik.solve(targets)
    assert result.residual.max() < 1e-3  # metres: every site within 1 mm
    solved = np.stack([ik.frame_positions(q) for q in result.qpos])
    # Knee and elbow flexion are fixed by the site distances alone: they must match.
    for chain in [("l_hip", "l_knee", "l_ankle"), ("r_shoulder", "r_elbow", "r_wrist")]:
        np.testing.assert_allclose(
            _hinge_angle(solved, *chain), _hinge_angle(targets, *chain), atol=np.radians(0.5)
        )
    np.testing.assert_allclose(result.qpos[:, :3], walk_qpos[:, :3], atol=0.02)


def test_first_frame_facing_backwards_is_found(body, ik, walk_qpos):
    """The rigid root fit starts a body turned half-way round near its answer."""
    turned = generate("walk", duration_s=0.2, fps=30.0).rotated_about_z(np.pi)
    q = body.qpos_from_motion(turned)
    targets = np.stack([ik.frame_positions(x) for x in q])
    assert ik.solve(targets).residual.max() < 1e-3


def test_joint_limits_hold_for_unreachable_targets(ik, body):
    rest = ik.frame_positions(ik.posture)
    targets = rest.copy()
    targets[BODY17.index("l_wrist")] += [0.0, 0.0, 3.0]  # far above the reach of the arm
    targets[BODY17.index("r_knee")] += [0.6, 0.0, 0.6]  # knee up past the hip
    result = ik.solve(targets[None])
    q = result.qpos[0]
    assert np.all(q >= ik.qpos_lower - 1e-6) and np.all(q <= ik.qpos_upper + 1e-6)
    at_bound = np.minimum(q - ik.qpos_lower, ik.qpos_upper - q) < 1e-3
    assert at_bound.sum() >= 2  # the stretched arm and the knee pushed against their ranges
    assert np.isfinite(result.residual).all()


def test_orientation_target_is_met(body):
    model = humanoid_model(body)
    ik = HumanoidIK(model, ("head", "l_wrist", "r_wrist"), orientation_cost=(1.0, 0.0, 0.0))
    q = body.qpos_from_motion(generate("wave", duration_s=0.1, fps=30.0))[0]
    targets = ik.frame_positions(q)
    head_rot = ik.configuration.get_transform_frame_to_world("head", "site").rotation().wxyz
    result = ik.solve(targets[None], orientations=np.tile(head_rot, (1, 3, 1)))
    solved_rot = ik.configuration.get_transform_frame_to_world("head", "site").rotation().wxyz
    assert result.residual.max() < 1e-3
    assert abs(np.dot(solved_rot, head_rot)) > np.cos(np.radians(1.0) / 2)


def test_motion_from_qpos_inverts_qpos_from_motion(body):
    motion = generate("walk", duration_s=0.5, fps=30.0)
    back = motion_from_qpos(body, body.qpos_from_motion(motion), motion.fps)
    np.testing.assert_allclose(body17_positions(back), body17_positions(motion), atol=1e-9)


def test_bad_input_is_refused(body):
    model = humanoid_model(body)
    with pytest.raises(BodyError, match="no sites"):
        HumanoidIK(model, ("nose",))
    ik = HumanoidIK(model, BODY17)
    with pytest.raises(BodyError, match="targets must be"):
        ik.solve(np.zeros((3, 5, 3)))
    with pytest.raises(BodyError, match="qpos must be"):
        motion_from_qpos(body, np.zeros((2, 5)), 30.0)


def test_solution_does_not_amplify_rounding(ik):
    """Targets moved by 1e-12 m (what BLAS rounding of another kernel does to the QP) move the
    whole solution, root and redundant joints included, by far less than a micrometre, even
    where the targets are out of reach (a 1.95 m subject on the 1.8 m avatar): each frame's
    iteration contracts (``IKSettings.damping``; measured 7e-11 rad; 2.8 rad with ``d = 1e-4``)."""
    tall = generate("box", Subject(height_m=1.95), duration_s=1.0, fps=30.0, seed=2)
    targets = body17_positions(tall)
    nudged = targets + 1e-12 * np.random.default_rng(0).standard_normal(targets.shape)
    assert np.abs(ik.solve(targets).qpos - ik.solve(nudged).qpos).max() < 1e-6

"""The least-squares IK: rotation logs as scipy's, a reachable pose recovered from a nearby
start, kept within the joint ranges."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body.ik import IKSettings
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.synthesis.avatargo.least_squares_ik import LeastSquaresIK, rotation_log
from avatarsim.synthesis.avatargo.synthesizer import ORIENTATION_COST, POSITION_COST, SITES


def test_rotation_log_is_scipys_rotation_vector():
    r = Rotation.random(50, random_state=0)
    r = r[r.magnitude() < np.pi - 1e-3]
    np.testing.assert_allclose(rotation_log(r.as_matrix()), r.as_rotvec(), atol=1e-9)
    np.testing.assert_allclose(rotation_log(np.eye(3)[None]), np.zeros((1, 3)))


def test_recovers_a_reachable_pose_within_the_ranges():
    """Goals read off a random in-range pose (sites' positions and rotations); from a start
    5 cm and ~0.05 rad per hinge away, 6 steps put every steered site within 1 mm (the
    neck, steered by position at a small weight, within 5 mm) and keep every hinge in its
    range."""
    model = build_body(load_rig("avatar").skeleton).model
    ik = LeastSquaresIK(
        model,
        SITES,
        position_cost=POSITION_COST,
        orientation_cost=ORIENTATION_COST,
        settings=IKSettings(),
    )
    rng = np.random.default_rng(0)
    truth = model.qpos0.copy()
    truth[7:] = np.clip(
        truth[7:] + rng.normal(0, 0.2, model.nv - 6), ik.qpos_lower[7:], ik.qpos_upper[7:]
    )
    truth[:7] = [0.3, 0.1, 0.9, *quat.normalize(np.array([1.0, 0.1, 0.05, 0.3]))]
    ik.frame_positions(truth)
    data = ik.configuration.data
    goals = data.site_xpos[ik.site_ids].copy()
    rotations = quat.from_matrix(data.site_xmat[ik.site_ids].reshape(-1, 3, 3))
    start = truth.copy()
    start[7:] += rng.normal(0, 0.05, model.nv - 6)
    start[:3] += 0.05
    q, residual, _ = ik.solve_frame(goals, start, rotations, 6)
    neck = SITES.index("neck")
    assert np.delete(residual, neck).max() < 1e-3 and residual[neck] < 5e-3
    assert (q[7:] >= ik.qpos_lower[7:] - 1e-12).all() and (q[7:] <= ik.qpos_upper[7:] + 1e-12).all()

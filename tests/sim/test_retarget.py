"""Retargeting onto the humanoid: own rig exactly, other sizes and real mocap under 2 cm."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body.ik import HumanoidIK, humanoid_model
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import Subject, generate
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.sim.retarget import retarget
from avatarsim.sim.retarget.feet import SWING_CLEARANCE_M, lift_toes, stance_feet, swinging_feet
from avatarsim.sim.retarget.sizing import fitted_body
from avatarsim.sim.soles import box_corners, corner_positions, foot_bodies, sole_boxes

BANDAI_WALK = "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"


def test_own_rig_is_reproduced():
    motion = generate("walk", duration_s=1.0, fps=30.0)
    body = build_body(motion.skeleton)
    qpos, out, residual_cm = retarget(motion, body)
    assert residual_cm.max() < 0.1  # 1 mm
    np.testing.assert_allclose(body17_positions(out), body17_positions(motion), atol=2e-3)
    assert qpos.shape == (motion.n_frames, 7 + len(body.hinges))


def test_other_size_avatar_fits_its_own_size():
    """A tall subject on the avatar rig: the fitted body takes its size, residual ~0."""
    motion = generate("walk", Subject(height_m=1.95), duration_s=1.0, fps=30.0)
    body = fitted_body(motion)
    assert body.stature == pytest.approx(1.95, rel=0.03)
    assert retarget(motion, level_feet=False).residual_cm.mean() < 0.1


def test_given_body_scales_the_targets():
    motion = generate("walk", Subject(height_m=1.95), duration_s=0.5, fps=30.0)
    small = build_body(generate("walk", duration_s=0.1).skeleton, height_m=1.6)
    _, out, residual_cm = retarget(motion, small)
    assert residual_cm.mean() < 0.5
    ratio = np.ptp(body17_positions(out)[..., 2]) / np.ptp(body17_positions(motion)[..., 2])
    assert ratio == pytest.approx(1.6 / 1.95, rel=0.05)


@pytest.mark.mocap
def test_joint_limits_hold(mocap_dir):
    motion = load_motion(mocap_dir / "cmu" / "09_01.bvh")[::4]
    body = fitted_body(motion)
    qpos, _, _ = retarget(motion, body)
    ranges = np.array([body.hinge_ranges[j][a] for j, a in body.hinges])
    assert np.all(qpos[:, 7:] >= ranges[:, 0] - 1e-6)
    assert np.all(qpos[:, 7:] <= ranges[:, 1] + 1e-6)


def test_rig_without_body17_is_refused():
    from avatarsim.avatar_models.motion import Motion
    from avatarsim.avatar_models.skeleton import Skeleton

    sk = Skeleton(["a", "b"], [-1, 0], np.array([[0, 0, 1.0], [0, 0, 0.5]]), name="blob")
    motion = Motion(sk, 30.0, np.zeros((2, 3)), np.tile([1.0, 0, 0, 0], (2, 2, 1)))
    with pytest.raises(MotionValueError, match="cannot retarget"):
        retarget(motion)


@pytest.mark.mocap
@pytest.mark.parametrize(
    "clip", ["cmu/16_35.bvh", "cmu/06_06.bvh", BANDAI_WALK], ids=["cmu_run", "cmu_bball", "bandai"]
)
def test_real_mocap_retargets_under_2cm(mocap_dir, clip):
    motion = load_motion(mocap_dir / clip)
    motion = motion[1::2] if motion.fps > 60 else motion  # frame 0 of CMU is a T-pose
    _, out, residual_cm = retarget(motion)
    p95 = np.percentile(residual_cm, 95)
    print(f"{clip}: residual mean {residual_cm.mean():.2f} cm, p95 {p95:.2f} cm")
    assert residual_cm.mean() < 2.0
    assert out.skeleton.name == "avatar"


def _lowest_sole_corners(body, qpos: np.ndarray) -> np.ndarray:
    """``(T, 2)`` height of the lowest sole-box corner of the left and right foot."""
    model = humanoid_model(body)
    data = mujoco.MjData(model)
    boxes = [sole_boxes(model, (foot,)) for foot in foot_bodies(model)]
    low = np.empty((qpos.shape[0], 2))
    for t, q in enumerate(qpos):  # MuJoCo evaluates one configuration per call
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        for side, geoms in enumerate(boxes):
            low[t, side] = corner_positions(data, geoms, box_corners(model, geoms))[..., 2].min()
    return low


@pytest.mark.mocap
def test_levelled_real_walk_stands_flat_and_swings_clear(mocap_dir):
    """With ``level_feet`` the Bandai walk stands on flat soles, lifts its swinging soles
    3 cm clear (so a simulated toe does not catch the floor) and digs into the floor nowhere
    by more than the toes' range allows (1.2 cm), on the body its skeleton builds."""
    motion = load_motion(mocap_dir / BANDAI_WALK)
    qpos, out, residual_cm = retarget(motion, level_feet=True)
    assert residual_cm.mean() < 1.0
    targets = body17_positions(motion)
    stance = stance_feet(targets, motion.fps)
    swing = swinging_feet(targets, motion.fps) & ~stance
    low = _lowest_sole_corners(build_body(out.skeleton), qpos)
    assert stance.sum() > 100 and swing.sum() > 100
    assert np.all((low[stance] > -0.002) & (low[stance] < 0.015))
    assert np.all(low[swing] > SWING_CLEARANCE_M - 0.001)
    assert low.min() > -0.015
    plain = _lowest_sole_corners(build_body(out.skeleton), retarget(motion).qpos)
    assert plain[swing].min() < SWING_CLEARANCE_M - 0.01  # the clearance is the repair's


def test_toes_bend_out_of_the_floor_about_the_ball():
    """Standing flat with the left toes bent 30 deg into the floor: lift_toes bends them
    back until the box is out (the nearest such angle, so not further than flat), and no
    body17 site moves."""
    body = build_body(load_rig("avatar").skeleton)
    model = humanoid_model(body)
    toe = model.jnt_qposadr[model.joint("Bip01 L Toe0:ry").id]
    bent = [model.qpos0.copy(), model.qpos0.copy()]
    bent[0][toe], bent[1][toe] = np.radians(30.0), np.radians(-30.0)
    qpos = np.array(bent)
    into = qpos[np.argmin(_lowest_sole_corners(body, qpos)[:, 0])][None]
    assert _lowest_sole_corners(body, into)[0, 0] < -0.01
    lifted = lift_toes(model, into)
    assert -1e-3 < _lowest_sole_corners(body, lifted)[0, 0] < 0.01
    assert abs(lifted[0, toe]) < abs(into[0, toe])
    ik = HumanoidIK(model, BODY17)
    np.testing.assert_allclose(ik.frame_positions(lifted[0]), ik.frame_positions(into[0]))

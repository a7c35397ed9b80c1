"""Exact offsets (eqs. 2-3): exact reconstruction of root, feet and head at zero strap offset
and noise when the avatar is the user; the fixed baseline is off by the straps."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.generator.subject import Subject
from avatarsim.render_cams.vr import Attachment
from avatarsim.synthesis.avatargo.offsets import exact_offsets, fixed_offsets
from avatarsim.synthesis.avatargo.study import EFFECTORS, ideal_user, setup_for
from avatarsim.synthesis.avatargo.synthesizer import AvatarGo
from avatarsim.synthesis.avatargo.walk_in import walk_in
from avatarsim.synthesis.base import FrameBatch, on_clock


def test_exact_offsets_follow_a_rigidly_carried_joint():
    """A joint carried rigidly with its tracker (any pose) is recovered by eqs. 2-3."""
    rng = np.random.default_rng(0)
    q0, qj = quat.from_scipy(Rotation.random(2, random_state=rng))
    p0, pj = rng.normal(size=(2, 3))
    off = exact_offsets(p0[None], q0[None], pj[None], qj[None])
    turn = quat.from_scipy(Rotation.random(5, random_state=rng))  # (5, 4) motions of the body
    shift = rng.normal(size=(5, 3))
    tracker_q = quat.mul(turn, q0)
    joint_q = quat.mul(turn, qj)
    pos, rot = off.joint_poses((shift + quat.rotate(turn, p0))[:, None], tracker_q[:, None])
    np.testing.assert_allclose(pos[:, 0], shift + quat.rotate(turn, pj), atol=1e-12)
    np.testing.assert_allclose(np.abs((rot[:, 0] * joint_q).sum(-1)), 1.0, atol=1e-12)


def test_fixed_offsets_invert_the_attachment():
    a = Attachment("pelvis", np.array([-0.1, 0.0, 0.05]), quat.from_axis_angle([0, 0, 1], 3.0))
    off = fixed_offsets([a])
    joint_q = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.array(0.4))
    joint_p = np.array([0.3, 0.2, 1.0])
    device_p = joint_p + quat.rotate(joint_q, a.position)
    pos, _ = off.joint_poses(device_p[None], quat.mul(joint_q, a.rotation)[None])
    np.testing.assert_allclose(pos[0], joint_p, atol=1e-12)


@pytest.mark.parametrize("solver", ["analytic", "mink"])
def test_exact_reconstruction_at_zero_offset_and_noise(solver):
    """Avatar = user, trackers at the nominal spots, no noise: the goals of root, feet and
    head are the user's joints to 1e-6 m on every frame (eqs. 2-3). The analytic solver puts
    root and feet on them to 1e-6 m too (placed, not solved), and its head, which follows the
    spine's bend by forward kinematics (eq. 4), to 1 mm (measured 0.05 mm max: the avatar's
    straight rest back against the user's curved one). mink's output sits on all four to 1 mm
    (its convergence tolerance; measured 0.5 mm max on this clip)."""
    # wave: a standing activity whose arms reach high (the hands' reach is exercised too)
    truth = generate("wave", Subject(), 1.0, 90.0, 0)
    user = ideal_user(0, heading_rad=0.7)
    setup = setup_for(user)
    synth = AvatarGo(
        truth.skeleton,
        walk_in(setup, truth, user.seed, user.heading_rad),
        fingers=False,
        solver=solver,
    )
    stream = on_clock(setup.sample(truth, seed=0))
    index = synth.device_index(FrameBatch.of_stream(stream))
    goals, _ = synth.goals(stream.positions[:, index], stream.quaternions[:, index])
    tracked = list(EFFECTORS.values())[:4]  # head, feet, root: the tracked goals
    rig_joints = truth.skeleton.indices([synth.body.rig.body17[j] for j in tracked])
    user_joints = truth.global_positions()[:, rig_joints]
    np.testing.assert_allclose(goals[:, :4], user_joints, atol=1e-6)
    out = synth.run(setup.sample(truth, seed=0))
    got = out.global_positions()[
        :, out.skeleton.indices([synth.body.rig.body17[j] for j in tracked])
    ]
    err = np.linalg.norm(got - user_joints, axis=-1)  # (T, 4) head, feet, root
    assert err.max() < 1e-3
    if solver == "analytic":
        assert err[:, 1:].max() < 1e-6
    # The controllers sit at the palms (the user's grip is the avatar's): mink as far as the
    # weak wrist orientation goal turns the hands (measured 9.4 mm at worst, 2 mm typical);
    # analytic as far as the arm reaches from the straight back's shoulder (0.9 mm).
    assert np.max(synth.palm_distance) < 0.015

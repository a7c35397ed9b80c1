"""Motion core: FK against hand-computed poses, resampling, slicing, mirroring, retiming."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionValueError, UnknownJointError
from avatarsim.avatar_models.motion import Motion, forward_kinematics
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.avatar_models.skeleton import Skeleton


def chain_skeleton() -> Skeleton:
    """root -> a (1 m along +X) -> b (0.5 m along +X)."""
    return Skeleton(["root", "a", "b"], [-1, 0, 1], [[0, 0, 1], [1, 0, 0], [0.5, 0, 0]])


def random_motion(rng: np.random.Generator, frames: int = 40, fps: float = 30.0) -> Motion:
    sk = load_rig("body17").skeleton
    rot = quat.from_scipy(
        Rotation.random(frames * sk.n_joints, random_state=rng), (frames, sk.n_joints)
    )
    return Motion(sk, fps, rng.normal(size=(frames, 3)), rot)


def test_fk_matches_hand_computed_chain():
    sk = chain_skeleton()
    rot = np.tile(quat.IDENTITY, (2, 3, 1))
    # Frame 1: root turned 90 deg about Z, joint a bent 90 deg about Y.
    rot[1, 0] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    rot[1, 1] = quat.from_axis_angle([0, 1, 0], np.pi / 2)
    m = Motion(sk, 10.0, np.array([[0, 0, 1.0], [2.0, 0, 1.0]]), rot)
    pos = m.global_positions()
    np.testing.assert_allclose(pos[0], [[0, 0, 1], [1, 0, 1], [1.5, 0, 1]], atol=1e-12)
    # Root at (2,0,1) facing +Y: a is 1 m along +Y; b's +X after Ry(90) points down (-Z).
    np.testing.assert_allclose(pos[1], [[2, 0, 1], [2, 1, 1], [2, 1, 0.5]], atol=1e-12)
    expected_b = Rotation.from_euler("ZY", [90, 90], degrees=True).as_matrix()
    np.testing.assert_allclose(m.fk()[1][1, 2], expected_b, atol=1e-12)


def test_fk_agrees_with_per_joint_scipy_composition():
    rng = np.random.default_rng(0)
    m = random_motion(rng)
    sk = m.skeleton
    pos = m.global_positions()
    t = 7
    glob = [None] * sk.n_joints
    ref = np.zeros((sk.n_joints, 3))
    for j in range(sk.n_joints):
        local = quat.to_scipy(m.local_rot[t, j])[0]
        p = sk.parents[j]
        if p < 0:
            glob[j], ref[j] = local, m.root_pos[t]
        else:
            glob[j] = glob[p] * local
            ref[j] = ref[p] + glob[p].apply(sk.offsets[j])
    np.testing.assert_allclose(pos[t], ref, atol=1e-12)
    np.testing.assert_allclose(
        quat.to_matrix(m.global_rotations()[t]), [g.as_matrix() for g in glob], atol=1e-12
    )


def test_bone_lengths_constant_under_fk():
    m = random_motion(np.random.default_rng(1))
    pos = m.global_positions()
    sk = m.skeleton
    lengths = np.linalg.norm(pos[:, 1:] - pos[:, sk.parents[1:]], axis=-1)
    np.testing.assert_allclose(
        lengths, np.broadcast_to(sk.bone_lengths[1:], lengths.shape), atol=1e-12
    )


def test_resample_keeps_duration_and_interpolates_by_slerp():
    sk = chain_skeleton()
    rot = np.tile(quat.IDENTITY, (2, 3, 1))
    rot[1, 1] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    m = Motion(sk, 1.0, np.array([[0, 0, 0], [1.0, 0, 0]]), rot)
    up = m.resample(4.0)
    assert up.n_frames == 5 and up.fps == 4.0
    assert up.duration_s == pytest.approx(m.duration_s)
    np.testing.assert_allclose(up.root_pos[:, 0], np.linspace(0, 1, 5))
    np.testing.assert_allclose(
        quat.angle(up.local_rot[:, 1]), np.linspace(0, np.pi / 2, 5), atol=1e-12
    )
    # Half way, joint b sits at 45 deg: slerp, not a straight-line blend of positions.
    b = up.global_positions()[2, 2] - up.global_positions()[2, 1]
    np.testing.assert_allclose(
        b, 0.5 * np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0]), atol=1e-12
    )


def test_resample_matches_scipy_slerp_per_joint():
    m = random_motion(np.random.default_rng(6), frames=12, fps=30.0)
    times = np.random.default_rng(7).uniform(0, m.duration_s, 50)
    expected = np.stack(
        [
            Slerp(m.times, quat.to_scipy(m.local_rot[:, j]))(times).as_matrix()
            for j in range(m.skeleton.n_joints)
        ],
        axis=1,
    )
    np.testing.assert_allclose(quat.to_matrix(m.sample(times).local_rot), expected, atol=1e-12)


def test_forward_kinematics_of_some_joints_equals_the_full_pass():
    m = random_motion(np.random.default_rng(8), frames=5, fps=30.0)
    pos, rot = m.fk()
    leaf = m.skeleton.n_joints - 1
    some_pos, some_rot = forward_kinematics(
        m.skeleton, m.root_pos, quat.to_matrix(m.local_rot), [leaf]
    )
    chain = [leaf]
    while m.skeleton.parents[chain[-1]] >= 0:
        chain.append(int(m.skeleton.parents[chain[-1]]))
    np.testing.assert_array_equal(some_pos[:, chain], pos[:, chain])
    np.testing.assert_array_equal(some_rot[:, chain], rot[:, chain])


def test_resample_round_trip_reproduces_original_frames():
    m = random_motion(np.random.default_rng(2), frames=10, fps=30.0)
    back = m.resample(90.0)[::3]
    np.testing.assert_allclose(back.global_positions(), m.global_positions(), atol=1e-9)
    assert back.fps == pytest.approx(30.0)


def test_retime_plays_faster_and_slower():
    m = random_motion(np.random.default_rng(3), frames=31, fps=30.0)
    fast = m.retime(2.0)
    assert fast.n_frames == 16
    np.testing.assert_allclose(fast.global_positions(), m[::2].global_positions(), atol=1e-9)
    assert m.retime(0.5).duration_s == pytest.approx(2 * m.duration_s)


def test_slicing_and_concatenation():
    m = random_motion(np.random.default_rng(4), frames=20)
    head, tail = m[:12], m[12:]
    joined = Motion.concatenate([head, tail], continue_root=False)
    np.testing.assert_allclose(joined.global_positions(), m.global_positions())
    shifted = Motion.concatenate([head, tail.translated([5.0, 5.0, 0.0])], continue_root=True)
    np.testing.assert_allclose(shifted.root_pos[12, :2], head.root_pos[-1, :2])
    with pytest.raises(MotionValueError):
        Motion.concatenate([m, m.resample(60.0)])
    with pytest.raises(MotionValueError):
        m[30:]


def test_mirror_reflects_positions_and_swaps_sides():
    m = random_motion(np.random.default_rng(5))
    mirrored = m.mirror()
    swap = m.skeleton.mirror_map()
    expected = m.global_positions()[:, swap] * np.array([1.0, -1.0, 1.0])
    np.testing.assert_allclose(mirrored.global_positions(), expected, atol=1e-12)
    np.testing.assert_allclose(
        mirrored.mirror().global_positions(), m.global_positions(), atol=1e-12
    )


def test_turn_carried_by_a_joint_below_a_static_root():
    """A static reference root above the hips (as Bandai's): turned at the hips, every joint
    from the hips down lands where turning the whole motion at the root puts it, and the
    root keeps its rotation."""
    rng = np.random.default_rng(8)
    sk = Skeleton(["ref", "hips", "leg"], [-1, 0, 1], [[0, 0, 0], [0.1, 0.2, 0.9], [0, 0, -0.5]])
    rot = quat.from_scipy(Rotation.random(20 * 3, random_state=rng), (20, 3))
    rot[:, 0] = quat.IDENTITY
    m = Motion(sk, 30.0, rng.normal(size=(20, 3)), rot)
    at_hips, at_root = m.rotated_about_z(0.7, carrier=1), m.rotated_about_z(0.7)
    np.testing.assert_allclose(
        at_hips.global_positions()[:, 1:], at_root.global_positions()[:, 1:], atol=1e-12
    )
    np.testing.assert_allclose(at_hips.fk()[1][:, 1:], at_root.fk()[1][:, 1:], atol=1e-12)
    np.testing.assert_array_equal(at_hips.local_rot[:, 0], m.local_rot[:, 0])


def test_relative_views():
    m = random_motion(np.random.default_rng(6))
    rel = m.relative_to("head")
    np.testing.assert_allclose(rel[:, m.skeleton.index("head")], 0.0, atol=1e-12)
    turned = m.rotated_about_z(0.7)
    np.testing.assert_allclose(
        turned.relative_to("pelvis", heading=True), m.root_relative(heading=True), atol=1e-9
    )
    with pytest.raises(UnknownJointError, match="unknown joint 'nose'"):
        m.relative_to("nose")


@pytest.mark.parametrize(
    "change",
    [
        {"fps": 0.0},
        {"root_pos": np.full((3, 3), np.nan)},
        {"local_rot": np.zeros((3, 17, 4))},
        {"local_rot": np.ones((3, 5, 4))},
    ],
)
def test_invalid_motion_raises_typed_error(change):
    sk = load_rig("body17").skeleton
    kw = dict(
        skeleton=sk,
        fps=30.0,
        root_pos=np.zeros((3, 3)),
        local_rot=np.tile(quat.IDENTITY, (3, 17, 1)),
    )
    kw.update(change)
    with pytest.raises(MotionValueError):
        Motion(**kw)

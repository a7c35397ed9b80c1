"""Orientations from tracked positions: Kinect V2's roll from the plane of a bone and its
child's (so it turns and flips with the positions), Azure's from its 32-joint rig (the thumb
turns the wrist), both against poses whose rotations are known by construction."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.kinect.orientations import tracked_orientations

V2, AZURE = load_rig("kinect_v2"), load_rig("azure_kinect")


def rest(rig, frames: int = 1) -> np.ndarray:
    return np.repeat(rig.skeleton.rest_positions()[None], frames, axis=0)


def turned(p: np.ndarray, rig, joints, about: str, rot: np.ndarray) -> np.ndarray:
    """``p`` with ``joints`` rotated by the matrix ``rot`` about joint ``about``."""
    sk = rig.skeleton
    out = p.copy()
    pivot = p[..., sk.index(about), :]
    for name in joints:
        j = sk.index(name)
        out[..., j, :] = pivot + (p[..., j, :] - pivot) @ rot.T
    return out


def about(axis, degrees: float) -> np.ndarray:
    return quat.to_matrix(quat.from_axis_angle(np.asarray(axis, float), np.radians(degrees)))


def relative_deg_and_axis(q_a: np.ndarray, q_b: np.ndarray):
    rel = quat.mul(q_b, quat.conj(q_a))
    angle = np.degrees(quat.angle(rel))
    axis = rel[..., 1:] / np.linalg.norm(rel[..., 1:], axis=-1, keepdims=True)
    return angle, axis


V2_FOREARM = ("WristLeft", "HandLeft", "HandTipLeft", "ThumbLeft")


def test_the_rest_pose_reports_identity_for_both_sensors():
    for rig in (V2, AZURE):
        q = tracked_orientations(rest(rig), rig)
        np.testing.assert_allclose(np.abs(q[..., 0]), 1.0, atol=1e-9)


def test_v2_elbow_roll_is_the_plane_of_upper_arm_and_forearm():
    """The left arm (along +Y at rest) with the forearm bent 90 deg forward (+X) and then 90
    deg up (+Z): the upper arm has not moved, only the plane of the two bones turned by 90
    deg about it, and that is what V2's elbow orientation says."""
    forward = turned(rest(V2), V2, V2_FOREARM, "ElbowLeft", about([0, 0, 1], -90.0))
    up = turned(rest(V2), V2, V2_FOREARM, "ElbowLeft", about([1, 0, 0], 90.0))
    elbow = V2.skeleton.index("ElbowLeft")
    a, b = tracked_orientations(forward, V2), tracked_orientations(up, V2)
    angle, axis = relative_deg_and_axis(a[0, elbow], b[0, elbow])
    assert abs(angle - 90.0) < 1e-6
    np.testing.assert_allclose(np.abs(axis), [0.0, 1.0, 0.0], atol=1e-9)


def test_v2_roll_of_a_nearly_straight_arm_flips_with_noise_azure_stays():
    """A left arm bent 8-12 deg forward with 1 cm of joint noise, 200 frames: V2's elbow
    roll jumps between the bone plane and the body's forward (spread of tens of degrees, 90
    deg jumps), Azure's, from the body's forward, moves only with the bone (a few deg)."""
    rng = np.random.default_rng(0)
    n = 200
    stats = {}
    for rig, elbow, forearm in (
        (V2, "ElbowLeft", V2_FOREARM),
        (AZURE, "ELBOW_LEFT", ("WRIST_LEFT", "HAND_LEFT", "HANDTIP_LEFT", "THUMB_LEFT")),
    ):
        frames = []
        for bend in rng.uniform(8.0, 12.0, n):
            p = turned(rest(rig), rig, forearm, elbow, about([0, 0, 1], -bend))[0]
            wrist = rig.skeleton.index(forearm[0])
            p[wrist] += rng.normal(0.0, 0.01, 3)
            frames.append(p)
        q = tracked_orientations(np.stack(frames), rig)[:, rig.skeleton.index(elbow)]
        stats[rig.name] = np.degrees(quat.angle(q))  # (n,) turn from the T-pose
    assert np.percentile(stats["kinect_v2"], 90) > 60.0
    assert np.percentile(stats["azure_kinect"], 90) < 5.0


def test_azure_wrist_roll_follows_the_thumb_v2_has_none():
    """The left hand turned 90 deg about the forearm (+Y at rest): the thumb goes round with
    it. Azure's wrist turns 90 deg about the forearm; V2's wrist has no roll to report."""
    for rig, wrist, hand, expected in (
        (AZURE, "WRIST_LEFT", ("HAND_LEFT", "HANDTIP_LEFT", "THUMB_LEFT"), 90.0),
        (V2, "WristLeft", ("HandLeft", "HandTipLeft", "ThumbLeft"), 0.0),
    ):
        p = turned(rest(rig), rig, hand, wrist, about([0, 1, 0], 90.0))
        q = tracked_orientations(p, rig)[0, rig.skeleton.index(wrist)]
        assert abs(np.degrees(quat.angle(q)) - expected) < 1e-6, rig.name


def test_a_lost_joint_gives_nan_orientations_where_it_is_needed_only():
    p = rest(V2)
    p[0, V2.skeleton.index("WristLeft")] = np.nan
    q = tracked_orientations(p, V2)[0]
    lost = ~np.all(np.isfinite(q), axis=-1)
    names = {V2.skeleton.names[j] for j in np.flatnonzero(lost)}
    # the bones that start or end at the wrist; the elbow, whose child bone is lost, takes
    # its roll from the body's forward as for a straight arm
    assert names == {"WristLeft", "HandLeft", "ThumbLeft"}

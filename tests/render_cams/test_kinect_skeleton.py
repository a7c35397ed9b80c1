"""Kinect skeleton streams: body17 joints, extra joints, orientations, tracking state, noise."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.kinect import (
    KinectPlacementError,
    SkeletonNoise,
    TrackingState,
    kinect_skeleton,
    look_at,
)
from avatarsim.render_cams.tracking import UnknownDeviceError
from tests.render_cams.kinect_builders import t_pose

BOXING = generate("box", duration_s=1.0, fps=90.0, seed=4)


@pytest.mark.parametrize("device", ["kinect-v2", "azure-kinect"])
def test_mapped_joints_equal_body17_without_noise(device):
    stream = kinect_skeleton(BOXING, device, noise=None)
    rig = load_rig("kinect_v2" if device == "kinect-v2" else "azure_kinect")
    expected = body17_positions(motion_at_rate(BOXING, 30.0))
    assert stream.positions.shape == (31, rig.skeleton.n_joints, 3)
    np.testing.assert_allclose(stream.timestamps, np.arange(31) / 30.0)
    np.testing.assert_allclose(stream.positions[:, rig.body17_indices()], expected, atol=1e-12)


def test_extra_joints_sit_where_the_rig_puts_them():
    stream = kinect_skeleton(BOXING, "azure-kinect", noise=None)
    p = {n: stream.positions[:, i] for i, n in enumerate(stream.joint_names)}
    spine = (p["SPINE_CHEST"] - p["PELVIS"]) / np.linalg.norm(p["NECK"] - p["PELVIS"], axis=1)[
        :, None
    ]
    axis = (p["NECK"] - p["PELVIS"]) / np.linalg.norm(p["NECK"] - p["PELVIS"], axis=1)[:, None]
    assert np.allclose(np.cross(spine, axis), 0.0, atol=1e-9)  # on the pelvis-neck line
    forearm = p["WRIST_LEFT"] - p["ELBOW_LEFT"]
    hand = p["HANDTIP_LEFT"] - p["WRIST_LEFT"]
    # A fist in boxing: the hand continues the forearm (no wrist flexion beyond ~60 degrees).
    cos = np.sum(forearm * hand, 1) / np.linalg.norm(forearm, axis=1) / np.linalg.norm(hand, axis=1)
    assert np.all(cos > 0.5)
    assert np.all(np.abs(np.linalg.norm(hand, axis=1) - 0.17) < 0.05)
    for face in ("NOSE", "EYE_LEFT", "EAR_RIGHT"):
        assert np.all(np.linalg.norm(p[face] - p["HEAD"], axis=1) < 0.15)
    head_forward = p["NOSE"] - p["HEAD"]
    ears = p["EAR_LEFT"] - p["EAR_RIGHT"]
    assert np.all(np.abs(np.sum(head_forward * ears, 1)) < 0.3 * 0.1 * 0.15)


def test_orientations_turn_rest_bones_onto_current_bones():
    for device, rig_name in (("kinect-v2", "kinect_v2"), ("azure-kinect", "azure_kinect")):
        stream = kinect_skeleton(BOXING, device, noise=None)
        sk = load_rig(rig_name).skeleton
        elbow, wrist = sk.index("ElbowLeft" if device == "kinect-v2" else "ELBOW_LEFT"), None
        wrist = sk.index("WristLeft" if device == "kinect-v2" else "WRIST_LEFT")
        rest_bone = sk.offsets[wrist] / np.linalg.norm(sk.offsets[wrist])
        bone = stream.positions[:, wrist] - stream.positions[:, elbow]
        bone /= np.linalg.norm(bone, axis=1, keepdims=True)
        # V2 orients the joint by its bone from the parent; Azure by the joint's own rotation
        # (the elbow's rotation carries the forearm).
        joint = wrist if device == "kinect-v2" else elbow
        turned = quat.rotate(stream.orientations[:, joint], np.broadcast_to(rest_bone, bone.shape))
        assert np.max(np.linalg.norm(turned - bone, axis=1)) < 0.05


def test_t_pose_facing_the_sensor_is_fully_tracked():
    stream = kinect_skeleton(t_pose(3), "kinect-v2", noise=None)  # the automatic set-up
    assert np.all(stream.states == TrackingState.TRACKED)
    pose = look_at([2.0, 0.0, 1.0], [0.0, 0.0, 1.0])  # 2 m in front, 1 m high
    stream = kinect_skeleton(t_pose(3), "kinect-v2", sensor_pose=pose, noise=None)
    assert np.all(stream.states == TrackingState.TRACKED)
    np.testing.assert_allclose(stream.camera_space()[0, 0], [0.0, 1.006 - 1.0, 2.0], atol=1e-9)


def test_arm_behind_the_body_is_inferred():
    # Turned to face +Y, the T-pose's left arm points away from a sensor on +X, behind the
    # torso; the right arm points towards the sensor (slightly off-line, so that the hand does
    # not hide the elbow).
    motion = t_pose(2, yaw=np.pi / 2)
    pose = look_at([2.0, -0.3, 1.43], [0.0, 0.0, 1.43])
    stream = kinect_skeleton(motion, "kinect-v2", sensor_pose=pose, noise=None)
    state = dict(zip(stream.joint_names, stream.states[0], strict=True))
    for joint in ("ElbowLeft", "WristLeft", "HandLeft", "HandTipLeft"):
        assert state[joint] == TrackingState.INFERRED, joint
    for joint in ("ElbowRight", "WristRight", "HandRight", "Head", "SpineBase"):
        assert state[joint] == TrackingState.TRACKED, joint


def test_joints_outside_the_view_are_not_tracked():
    pose = look_at([0.8, 0.0, 1.0], [0.0, 0.0, 1.0])  # too close to see head and feet
    stream = kinect_skeleton(t_pose(1), "kinect-v2", sensor_pose=pose, noise=None)
    state = dict(zip(stream.joint_names, stream.states[0], strict=True))
    assert state["Head"] == state["FootLeft"] == TrackingState.NOT_TRACKED
    assert state["SpineMid"] == TrackingState.TRACKED


def test_noise_is_larger_when_inferred_and_reproducible():
    motion = t_pose(400, yaw=np.pi / 2)
    pose = look_at([2.0, -0.3, 1.43], [0.0, 0.0, 1.43])
    model = SkeletonNoise(tracked_m=0.01, correlation_s=0.0)
    clean = kinect_skeleton(motion, "kinect-v2", pose, noise=None)
    noisy = kinect_skeleton(motion, "kinect-v2", pose, seed=7, noise=model)
    again = kinect_skeleton(motion, "kinect-v2", pose, seed=7, noise=model)
    assert np.array_equal(noisy.positions, again.positions) and noisy.meta["seed"] == 7
    error = noisy.positions - clean.positions
    names = list(noisy.joint_names)
    assert error[:, names.index("SpineMid")].std() == pytest.approx(0.01, rel=0.1)
    assert error[:, names.index("ElbowRight")].std() == pytest.approx(0.01, rel=0.1)
    assert error[:, names.index("WristRight")].std() == pytest.approx(0.02, rel=0.1)  # extremity
    assert error[:, names.index("ElbowLeft")].std() == pytest.approx(0.03, rel=0.1)  # inferred


def test_bad_inputs_raise_typed_errors():
    with pytest.raises(UnknownDeviceError, match="kinect-one"):
        kinect_skeleton(t_pose(1), "kinect-one")
    inside = look_at([0.0, 0.0, 1.0], [1.0, 0.0, 1.0])  # at the pelvis
    with pytest.raises(KinectPlacementError, match="inside the body"):
        kinect_skeleton(t_pose(1), "azure-kinect", sensor_pose=inside)
    with pytest.raises(KinectPlacementError, match="orthonormal"):
        kinect_skeleton(t_pose(1), "azure-kinect", sensor_pose=np.diag([2.0, 1.0, 1.0, 1.0]))

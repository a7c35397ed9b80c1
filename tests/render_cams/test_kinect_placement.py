"""The Kinect set up for a take: facing the performer, the whole trajectory in range and view
where the sensor's range allows; NotTracked (not an error) where it does not."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.kinect import TrackingState, kinect_skeleton
from avatarsim.render_cams.kinect.depth import BODY_INDEX_NONE, KinectDepthCamera
from avatarsim.render_cams.kinect.placement import (
    DEFAULT_HEIGHT_M,
    KinectPlacementError,
    default_sensor_pose,
    in_view,
    mean_facing,
    performer_distance,
    yaw_pitch_pose,
)
from avatarsim.render_cams.kinect.sensors import get_sensor
from avatarsim.render_cams.scene import BodyScene
from tests.render_cams.kinect_builders import t_pose, t_pose_walk

NOT_TRACKED = TrackingState.NOT_TRACKED


@pytest.mark.parametrize("device", ["kinect-v2", "azure-kinect", "azure-kinect-wfov-binned"])
def test_sensor_faces_the_performer_and_keeps_a_short_walk_in_view(device):
    # 2 s walking 1 m/s along +Y while facing +X: the sensor stands in +X looking back (-X).
    motion = t_pose_walk(61, (0.0, 1.0))
    pose = default_sensor_pose(motion, device)
    eye, axis = pose[:3, 3], pose[:3, 2]
    assert eye[2] == pytest.approx(DEFAULT_HEIGHT_M)
    assert eye[0] > 1.0 and abs(eye[1] - 1.0) < 1e-6  # in front, at the mean position sideways
    assert axis[0] < -0.95 and abs(axis[1]) < 1e-6  # looking back at the performer
    stream = kinect_skeleton(motion, device, pose, noise=None)
    assert not np.any(stream.states == NOT_TRACKED)
    near, far = get_sensor(device).range_m
    depth = performer_distance(pose, motion)
    assert near < depth.min() and depth.max() < far


def test_sensor_is_as_close_as_the_whole_body_allows():
    # Standing still: the nearest distance with the whole body in view, not an arbitrary 2 m.
    motion = t_pose(2)
    sensor = get_sensor("kinect-v2")
    pose = default_sensor_pose(motion, sensor)
    depth = float(performer_distance(pose, motion)[0])
    assert 1.2 < depth < 2.2
    joints = body17_positions(motion)
    closer = pose.copy()
    closer[:3, 3] += 0.3 * pose[:3, 2]  # 30 cm closer: the head or feet leave the image
    assert in_view(joints, pose, sensor).all() and not in_view(joints, closer, sensor).all()


def test_frames_out_of_range_are_not_tracked_not_an_error():
    # Walking 8 m away from where the sensor faces: longer than the 0.5-4.5 m range.
    motion = t_pose_walk(8 * 30 + 1, (-1.0, 0.0))
    pose = default_sensor_pose(motion, "kinect-v2")
    stream = kinect_skeleton(motion, "kinect-v2", pose, noise=None)
    lost = np.all(stream.states == NOT_TRACKED, axis=1)
    depth = performer_distance(pose, motion)
    assert lost.any() and not lost.all()
    assert np.all(depth[lost] > get_sensor("kinect-v2").range_m[1] - 0.5)  # the far end
    assert np.all(np.isfinite(stream.positions))
    # The recorded frame has no body and no joint positions, as the SDKs report it.
    frame = stream.frame_dict(int(np.flatnonzero(lost)[0]))
    assert frame["body_tracked"] is False
    assert all(j["position_world_m"] is None for j in frame["joints"])
    assert {j["tracking_state"] for j in frame["joints"]} == {"NOT_TRACKED"}
    assert stream.frame_dict(int(np.flatnonzero(~lost)[0]))["body_tracked"] is True
    # Noise is not added to joints the sensor does not report.
    noisy = kinect_skeleton(motion, "kinect-v2", pose, seed=1)
    np.testing.assert_array_equal(noisy.positions[lost], stream.positions[lost])


def test_performer_walking_through_the_sensor_is_recorded():
    # The sensor stands on the path; it is inside the body for a few frames only.
    motion = t_pose_walk(4 * 30 + 1, (1.0, 0.0))
    pose = yaw_pitch_pose([2.0, 0.0, 1.0], np.pi)
    stream = kinect_skeleton(motion, "kinect-v2", pose, noise=None)
    assert np.all(stream.states[60] == NOT_TRACKED)  # the sensor is at the pelvis at 2 s
    assert np.any(stream.states[0] == TrackingState.TRACKED)
    with pytest.raises(KinectPlacementError, match="every frame"):
        kinect_skeleton(t_pose(3), "kinect-v2", yaw_pitch_pose([0.0, 0.0, 1.0], 0.0))
    with pytest.raises(KinectPlacementError, match="below the floor"):
        kinect_skeleton(t_pose(3), "kinect-v2", yaw_pitch_pose([2.0, 0.0, -0.1], np.pi))


def test_automatic_set_up_stands_on_a_tv_bench_measured_from_the_floor_in_its_depth():
    """The automatic set-up puts the sensor 0.9 m above the floor (a TV-bench height, inside
    Microsoft's 0.6-1.8 m placement guidance), measured as a Kinect SDK finds its floor
    plane: the floor pixels of a clean depth frame back-projected through the intrinsics
    and fitted by a plane in camera coordinates; the sensor's height is its distance to it."""
    motion = t_pose(1)
    sensor = get_sensor("kinect-v2")
    scene = BodyScene(motion.skeleton)
    try:
        scene.update(motion, 0)
        frame = KinectDepthCamera(sensor, default_sensor_pose(motion, sensor), None).capture(
            scene, None
        )
    finally:
        scene.close()
    v, u = np.nonzero((frame.body_index == BODY_INDEX_NONE) & (frame.depth_mm > 0))  # floor
    z = frame.depth_m[v, u]
    K = sensor.K
    points = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z], -1)
    assert len(points) > 10_000
    centre = points.mean(0)
    normal = np.linalg.svd(points - centre, full_matrices=False)[2][-1]  # (3,) unit
    assert abs(normal[1]) > 0.95  # world up is near the camera's y axis: pitched a little
    assert abs(centre @ normal) == pytest.approx(0.9, abs=0.005)


def test_yaw_and_pitch_pose():
    pose = yaw_pitch_pose([1.0, 2.0, 0.9], np.pi / 2, np.radians(-10))
    np.testing.assert_allclose(pose[:3, 3], [1.0, 2.0, 0.9])
    np.testing.assert_allclose(
        pose[:3, 2], [0.0, np.cos(np.radians(10)), -np.sin(np.radians(10))], atol=1e-12
    )
    assert pose[2, 1] < 0  # image y (down) points down in the world
    with pytest.raises(KinectPlacementError):
        yaw_pitch_pose([0, 0, 1], 0.0, np.pi / 2)


def test_mean_facing_of_a_turned_performer():
    np.testing.assert_allclose(mean_facing(t_pose(2, yaw=np.pi / 2)), [0.0, 1.0], atol=1e-9)


REAL_CLIPS = (
    "cmu/09_01.bvh",  # a 4.4 m run in 1.3 s
    "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh",  # an 8 m straight walk
)


def _path_length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points[:, :2], axis=0), axis=1).sum())


@pytest.mark.mocap
@pytest.mark.parametrize("clip", REAL_CLIPS)
@pytest.mark.parametrize("device", ["kinect-v2", "azure-kinect"])
def test_real_takes_stay_tracked_and_in_view(mocap_dir, clip, device):
    """Both takes are longer than any Kinect sees whole: a standing body (feet to head) fills
    the 60-65 deg vertical field of view from about 1.6 m, so at most the 1.6 m to far-range
    stretch (2.9 m for Kinect V2, 2.3 m for Azure NFOV, less the body's own depth) of a path
    towards the sensor is seen whole. The sensor keeps such a stretch in view, every joint
    inside range and view is reported, and a part of the take that fits is tracked whole."""
    from avatarsim.sim.humanoid import humanoid_for  # the humanoid for a foreign rig (Bandai)

    humanoid = humanoid_for(load_motion(mocap_dir / clip))
    body, motion = humanoid.body, humanoid.motion
    motion = motion[:: max(1, int(round(motion.fps / 30)))]
    sensor = get_sensor(device)
    near, far = sensor.range_m
    joints = body17_positions(motion)

    pose = default_sensor_pose(motion, device)
    stream = kinect_skeleton(motion, device, pose, noise=None, body=body)
    seen = in_view(joints, pose, sensor).all(axis=1)  # (T,) the whole body in range and view
    tracked = stream.states != NOT_TRACKED
    assert seen.sum() >= 10 and tracked[seen].mean() > 0.99
    pelvis = joints[:, INDEX["pelvis"]]
    assert _path_length(pelvis[seen]) >= 1.5
    assert np.median(performer_distance(pose, motion)[seen]) < far

    # A part of the take 1.5 m long fits every sensor's range: all of it is tracked.
    travelled = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pelvis[:, :2], axis=0), axis=1))]
    part = motion[: int(np.searchsorted(travelled, 1.5))]
    pose = default_sensor_pose(part, device)
    stream = kinect_skeleton(part, device, pose, noise=None, body=body)
    assert part.n_frames >= 10 and not np.any(stream.states == NOT_TRACKED)
    assert in_view(body17_positions(part), pose, sensor).all()

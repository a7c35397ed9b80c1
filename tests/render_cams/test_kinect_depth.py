"""Rendered Kinect depth: a wall and the floor against geometry, range, body index, files."""

from __future__ import annotations

import cv2
import numpy as np
import pyrender
import pytest
import trimesh

from avatarsim.render_cams.kinect import get_sensor, look_at
from avatarsim.render_cams.kinect.depth import KinectDepthCamera
from avatarsim.render_cams.kinect.noise import depth_edge_partner
from avatarsim.render_cams.scene import BodyScene
from tests.render_cams.kinect_builders import t_pose

SENSOR = get_sensor("kinect-v2")
POSE = look_at([1.0, 0.0, 1.0], [0.0, 0.0, 1.0])  # 1 m in front of the user, 1 m high


@pytest.fixture(scope="module")
def user_scene():
    """The T-pose user on the floor, shared by the module's tests (one GL context)."""
    motion = t_pose(1)
    scene = BodyScene(motion.skeleton)
    scene.update(motion, 0)
    yield scene, motion
    scene.close()


@pytest.fixture
def scene_with_wall(user_scene):
    """The user in front of a 6 m x 3 m wall 3 m from the sensor (the plane x = -2)."""
    scene, motion = user_scene
    wall = trimesh.creation.box(extents=[0.1, 6.0, 3.0])
    wall.apply_translation([-2.05, 0.0, 1.5])
    node = scene.scene.add(pyrender.Mesh.from_trimesh(wall))
    yield scene, motion
    scene.scene.remove_node(node)


def test_wall_depth_and_noise_match_the_model(scene_with_wall):
    scene, _ = scene_with_wall
    clean = KinectDepthCamera(SENSOR, POSE, noise=None).capture(scene, np.random.default_rng(0))
    wall = np.abs(clean.depth_m - 3.0) < 1e-3
    assert wall.mean() > 0.4
    camera = KinectDepthCamera(SENSOR, POSE)
    rng = np.random.default_rng(1)
    frames = np.stack([camera.capture(scene, rng).depth_m for _ in range(6)])
    # Over 4 px from depth edges (lateral jitter, flying pixels) the wall reads 3 m +- sigma.
    edges = cv2.dilate(
        (depth_edge_partner(clean.depth_m, 0.1) > 0).astype(np.uint8), np.ones((9, 9))
    )
    keep = wall & (edges == 0)
    residual = (frames - 3.0)[:, keep]
    # The wall is frontal: a pixel's incidence angle is that of its ray to the optical axis.
    v, u = np.nonzero(keep)
    K = SENSOR.K
    theta = np.arctan(np.hypot((u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1]))
    sigma = SENSOR.noise.axial_sigma_m(3.0, theta)  # 2.7 mm on the axis (Fankhauser 2015)
    normalised = residual / np.hypot(sigma, 1e-3 / np.sqrt(12))  # + mm quantisation
    assert normalised.std() == pytest.approx(1.0, abs=0.03)
    assert abs(residual.mean()) < 0.2e-3
    assert np.percentile(np.abs(normalised), 99.9) < 4.5


def test_floor_depth_matches_ray_plane_intersections_and_range(user_scene):
    scene, _ = user_scene
    frame = KinectDepthCamera(SENSOR, POSE, noise=None).capture(scene, None)
    h, w = frame.depth_mm.shape
    v, u = np.mgrid[0:h, 0:w]
    K = SENSOR.K
    rays = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones((h, w))], -1)
    # Floor depth along each ray, and at the pixel's top and bottom edges (half a pixel
    # either way: the rasteriser samples within the pixel).
    floor_depth, lower, upper = (
        _floor_depth(rays + [0.0, dv / K[1, 1], 0.0]) for dv in (0.0, -0.5, 0.5)
    )
    # The floor next to the body: labels and depth agree, but keep off the silhouette.
    near_body = cv2.dilate((frame.body_index == 0).astype(np.uint8), np.ones((5, 5))) > 0
    floor = ~near_body & np.isfinite(floor_depth)
    in_range = floor & (upper <= 4.4) & np.isfinite(lower)
    beyond = floor & (floor_depth >= 4.6)
    assert in_range.sum() > 10_000 and beyond.sum() > 1000
    depth = frame.depth_m[in_range]
    inside = (depth >= upper[in_range] - 1e-3) & (depth <= lower[in_range] + 1e-3)
    assert inside.mean() > 0.99
    assert np.all(frame.depth_mm[beyond] == 0)
    sky = ~near_body & ~np.isfinite(floor_depth)
    assert sky.sum() > 1000 and np.all(frame.depth_mm[sky] == 0)  # no return


def test_body_index_covers_the_projected_silhouette(scene_with_wall):
    scene, motion = scene_with_wall
    mesh = scene.body.to_trimesh(motion, frame=0)
    cam = (mesh.vertices - POSE[:3, 3]) @ POSE[:3, :3]
    K = SENSOR.K
    uv = cam[:, :2] / cam[:, 2:] * [K[0, 0], K[1, 1]] + K[:2, 2]
    silhouette = np.zeros((SENSOR.height, SENSOR.width), np.uint8)
    for triangle in np.rint(uv[mesh.faces]).astype(np.int32):  # one call each: no even-odd
        cv2.fillConvexPoly(silhouette, triangle, 1)
    silhouette = silhouette.astype(bool)
    for noise, min_iou in ((None, 0.97), ("default", 0.9)):
        camera = KinectDepthCamera(SENSOR, POSE, noise=noise)
        body = camera.capture(scene, np.random.default_rng(2)).body_index == 0
        iou = (body & silhouette).sum() / (body | silhouette).sum()
        assert iou > min_iou, (noise, iou)


def _floor_depth(rays: np.ndarray) -> np.ndarray:
    """``(H, W)`` camera-z depth where camera rays ``(H, W, 3)`` (z = 1) meet the floor."""
    down = (rays @ POSE[:3, :3].T)[..., 2]
    with np.errstate(divide="ignore"):
        return np.where(down < 0, -POSE[2, 3] / down, np.inf)

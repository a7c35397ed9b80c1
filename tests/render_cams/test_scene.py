"""BodyScene: OpenCV camera conventions checked against an analytic pinhole projection."""

import cv2
import numpy as np
import pyrender
import pytest
import trimesh

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.scene import BodyScene, SceneError, pinhole_K

# A camera 3 m in front of the origin looking back along -X (OpenCV axes as columns).
LOOK_BACK = np.stack([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]], axis=1)


@pytest.fixture(scope="module")
def scene():
    motion = generate("wave", duration_s=0.2, fps=30)
    with BodyScene(motion.skeleton) as s:
        s.update(motion, 0)
        yield s


def _pose(rotation, centre):
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, centre
    return pose


def test_sphere_lands_on_pinhole_projection_with_its_depth(scene):
    centre = np.array([1.8, 0.25, 1.3])
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.02)
    node = scene.scene.add(pyrender.Mesh.from_trimesh(sphere), pose=_pose(np.eye(3), centre))
    try:
        pose = _pose(LOOK_BACK, [3.0, 0.0, 1.0])
        K = pinhole_K(np.radians(40.0), 320, 240)
        K[0, 2] += 7.0  # an off-centre principal point must be honoured too
        color, depth = scene.render(pose, K, 320, 240)
    finally:
        scene.scene.remove_node(node)
    cam = LOOK_BACK.T @ (centre - pose[:3, 3])
    expected = (K @ cam)[:2] / cam[2]
    rows, cols = np.nonzero((depth > 0) & (depth < cam[2] + 0.03))
    assert color.shape == (240, 320, 3) and color.dtype == np.uint8
    assert np.hypot(cols.mean() - expected[0], rows.mean() - expected[1]) < 0.5
    assert depth[rows, cols].min() == pytest.approx(cam[2] - 0.02, abs=0.003)


def test_body_parts_label_the_body_and_only_the_body(scene):
    pose = _pose(LOOK_BACK, [3.0, 0.0, 1.0])
    K = pinhole_K(np.radians(60.0), 160, 120)
    depth, parts = scene.render_depth_and_parts(pose, K, 160, 120)
    labels = np.unique(parts)
    assert labels[0] == 0 and labels[-1] <= len(scene.part_names) and len(labels) > 10
    # The body stands within 0.5 m of the origin, 3 m from the camera; the floor is label 0.
    # One pass: every labelled pixel, silhouette edges included, has the body's depth.
    body = depth[parts > 0]
    assert np.all((body > 2.4) & (body < 3.6))
    assert np.any((parts == 0) & (depth > 3.6))
    # The colour pass sees the same depth at every pixel (same single-sampled rasteriser).
    _, colour_depth = scene.render(pose, K, 160, 120)
    np.testing.assert_allclose(colour_depth, depth, atol=1e-4)
    np.testing.assert_array_equal(scene.render_parts(pose, K, 160, 120), parts)


@pytest.mark.parametrize("image_axis", [0, 1])  # 0: depth varies along columns, 1: rows
def test_depth_lands_within_a_tenth_of_a_pixel_of_cv2_project_points(scene, image_axis):
    """A plane tilted 50 deg about the camera's y (or x) axis: its depth varies along image
    columns (rows) only. The point of the plane at a pixel's rendered depth, projected by
    cv2.projectPoints, must land on that pixel's centre."""
    width, height = 320, 240
    K = pinhole_K(np.radians(50.0), width, height)
    K[image_axis, 2] += 3.3  # off-centre principal point
    other = 1 - image_axis
    tilt = np.radians(50.0)
    # The plane n . X = 2 cos(tilt) in camera coordinates, n = (sin, 0, cos) or (0, sin, cos).
    normal = np.array([0.0, 0.0, np.cos(tilt)])
    normal[image_axis] = np.sin(tilt)
    in_plane = np.cross(normal, np.eye(3)[other])
    in_plane /= np.linalg.norm(in_plane)
    plane_in_camera = _pose(np.stack([in_plane, np.cross(normal, in_plane), normal], 1), [0, 0, 2])
    plane = trimesh.Trimesh(
        [[-5.0, -5.0, 0.0], [5.0, -5.0, 0.0], [5.0, 5.0, 0.0], [-5.0, 5.0, 0.0]],
        [[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]],  # both sides
        process=False,
    )
    camera_pose = _pose(np.eye(3), [0.0, 0.0, -60.0])  # below the floor, looking up: the
    # floor and body are beyond the far plane, only the plane is seen
    node = scene.scene.add(pyrender.Mesh.from_trimesh(plane), pose=camera_pose @ plane_in_camera)
    try:
        depth, _ = scene.render_depth_and_parts(camera_pose, K, width, height)
    finally:
        scene.scene.remove_node(node)
    # The pixel line through (near) the principal point, and the plane point at each depth z:
    # its other coordinate from the line's pixel, its own from the plane equation.
    line_pixel = int(round(K[other, 2]))
    line = depth[:, line_pixel] if image_axis == 1 else depth[line_pixel, :]
    pixels = np.nonzero((line > 1.0) & (line < 4.0))[0]
    z = line[pixels].astype(float)
    points = np.zeros((len(z), 3))
    points[:, image_axis] = (2.0 - z) * np.cos(tilt) / np.sin(tilt)
    points[:, other] = (line_pixel - K[other, 2]) * z / K[other, other]
    points[:, 2] = z
    projected, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), K, np.zeros(5))
    assert len(pixels) > 100
    assert np.max(np.abs(projected[:, 0, image_axis] - pixels)) < 0.1


def test_closing_one_scene_leaves_the_others_working(scene):
    motion = generate("wave", duration_s=0.2, fps=30)
    pose = _pose(LOOK_BACK, [3.0, 0.0, 1.0])
    K = pinhole_K(np.radians(60.0), 64, 48)
    first, second = BodyScene(motion.skeleton), BodyScene(motion.skeleton)
    for s in (first, second):
        s.update(motion, 0)
        s.render(pose, K, 64, 48)
    first.close()
    _, depth = second.render(pose, K, 64, 48)
    second.close()
    _, parts = scene.render_depth_and_parts(pose, K, 64, 48)  # the module's scene lives on
    assert np.any(depth > 0) and np.any(parts > 0)


@pytest.mark.parametrize("K", [np.diag([-100.0, 100.0, 1.0]), np.eye(2), np.full((3, 3), np.nan)])
def test_bad_intrinsics_raise(scene, K):
    with pytest.raises(SceneError):
        scene.render(np.eye(4), K, 64, 48)


def test_mujoco_still_renders_after_the_last_scene_closes():
    """Closing a scene must not terminate the shared EGL display: MuJoCo's renderer (the
    scenario's pictures, after its cameras) initialises that display once, at import."""
    from avatarsim.sim.humanoid import humanoid_for
    from avatarsim.sim.render import render_frames

    motion = generate("wave", duration_s=0.2, fps=30)
    h = humanoid_for(motion)
    render_frames(h.model, h.qpos, [0], 64, 64)  # MuJoCo's EGL display is initialised now
    with BodyScene(h.body) as s:
        s.update(h.motion, 0)
        pose = np.eye(4)
        pose[:3, 3] = [3.0, 0.0, 1.0]
        pose[:3, :3] = [[0, 0, -1], [-1, 0, 0], [0, 1, 0]]  # OpenCV axes looking along -X
        s.render(pose, pinhole_K(np.radians(60.0), 64, 64), 64, 64)
    frame = render_frames(h.model, h.qpos, [0], 64, 64)[0]
    assert frame.std() > 0

"""Fisheye model and rendering against OpenCV's ``cv2.fisheye`` and analytic cases."""

import cv2
import numpy as np
import pyrender
import pytest
import trimesh

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.fisheye.model import FisheyeModel, IntrinsicsError
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.scene import BodyScene

D_TEST = (0.05, 0.01, -0.002, 0.0005)


@pytest.fixture(scope="module")
def empty_scene():
    """A scene whose body is far away (50 m), so only the floor and test objects are seen."""
    motion = generate("wave", duration_s=0.2, fps=30).translated(np.array([50.0, 0.0, 0.0]))
    with BodyScene(motion.skeleton) as scene:
        scene.update(motion, 0)
        yield scene


def test_paper_fov_and_intrinsics_round_trip():
    model = FisheyeModel.from_fov(150.0, 120.0, 640, 480, D=D_TEST)
    assert np.degrees(model.fov_rad) == pytest.approx([150.0, 120.0], abs=1e-6)
    rays, inside = model.rays()
    uv, ok = model.project(rays[inside])
    v, u = np.nonzero(inside)
    assert ok.all() and np.abs(uv - np.c_[u, v]).max() < 1e-6
    # Where OpenCV's undistortPoints is defined (theta_d <= 90 deg), the rays are its rays.
    pixels = np.c_[u, v].astype(float)[::97]
    theta_d = np.hypot(*((pixels - model.K[:2, 2]) / np.diag(model.K)[:2]).T)
    pixels = pixels[theta_d < np.pi / 2]
    xy = cv2.fisheye.undistortPoints(pixels[:, None], model.K, model.D)[:, 0]
    ours = model.unproject(pixels)
    assert np.abs(ours[:, :2] / ours[:, 2:] - xy).max() < 1e-6


def test_equidistant_projection_is_f_theta():
    model = FisheyeModel.from_fov(D=(0.0, 0.0, 0.0, 0.0))
    theta = np.radians([0.0, 20.0, 45.0, 70.0])
    points = np.stack([np.sin(theta), np.zeros(4), np.cos(theta)], axis=1)  # along +x
    uv, ok = model.project(points)
    assert ok.all()
    np.testing.assert_allclose(uv[:, 0] - model.K[0, 2], model.K[0, 0] * theta, atol=1e-9)
    _, behind = model.project(np.array([[0.1, 0.0, -1.0]]))
    assert not behind[0]


@pytest.mark.parametrize(
    "kwargs",
    [
        {"K": np.diag([-200.0, 200.0, 1.0]) + [[0, 0, 319.5], [0, 0, 239.5], [0, 0, 0]]},
        {"D": np.zeros(5)},
        {"D": (-0.5, 0.0, 0.0, 0.0)},  # folds the image
        {"K": np.array([[80.0, 0, 319.5], [0, 80.0, 239.5], [0, 0, 1]])},  # FOV > 180 deg
    ],
)
def test_impossible_intrinsics_raise_with_reason(kwargs):
    base = FisheyeModel.from_fov()
    args = {"K": base.K, "D": base.D, **kwargs}
    with pytest.raises(IntrinsicsError, match=r"\w+"):
        FisheyeModel(**args)
    with pytest.raises(IntrinsicsError):
        FisheyeModel.from_fov(200.0, 120.0)


def test_rendered_sphere_lands_on_opencv_projection(empty_scene):
    # Half resolution keeps the test fast; the property is resolution independent.
    model = FisheyeModel.from_fov(D=D_TEST).scaled(0.5)
    renderer = FisheyeRenderer(empty_scene, model)
    pose = np.eye(4)  # looking along +Y (world) from 1.2 m up, away from everything
    pose[:3, :3] = np.stack([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]], axis=1)
    pose[:3, 3] = [0.0, 3.0, 1.2]
    sphere = pyrender.Mesh.from_trimesh(trimesh.creation.icosphere(subdivisions=3, radius=0.012))
    rng = np.random.default_rng(1)
    for theta_deg in (0.0, 30.0, 55.0, 70.0):
        phi = rng.uniform(0, 2 * np.pi)
        theta = np.radians(theta_deg)
        cam = 0.5 * np.array(
            [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]
        )
        world = pose[:3, :3] @ cam + pose[:3, 3]
        node_pose = np.eye(4)
        node_pose[:3, 3] = world
        node = empty_scene.scene.add(sphere, pose=node_pose)
        try:
            color, rng_img = renderer.render(pose)
        finally:
            empty_scene.scene.remove_node(node)
        rows, cols = np.nonzero((rng_img > 0.45) & (rng_img < 0.52))
        expected, _ = cv2.fisheye.projectPoints(
            cam[None, None], np.zeros(3), np.zeros(3), model.K, model.D
        )
        assert len(rows) > 3
        assert np.hypot(cols.mean() - expected[0, 0, 0], rows.mean() - expected[0, 0, 1]) < 1.0
        assert rng_img[rows, cols].min() == pytest.approx(0.5 - 0.012, abs=0.004)
    assert color.shape == (240, 320, 3)


def test_corners_beyond_the_image_circle_see_nothing(empty_scene):
    model = FisheyeModel.from_fov(D=(0.0, 0.0, 0.0, 0.0)).scaled(0.25)  # equidistant
    _, inside = model.rays()
    assert not inside[0, 0] and inside[model.height // 2, model.width // 2]
    color, range_m = FisheyeRenderer(empty_scene, model, face_size=64).render(np.eye(4))
    assert range_m[0, 0] == 0 and color[0, 0].sum() == 0

"""BodyScene: OpenCV camera conventions checked against an analytic pinhole projection."""

import numpy as np
import pyrender
import pytest
import trimesh

from avatar_models.generator import generate
from render_cams.scene import BodyScene, SceneError, pinhole_K

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
    parts = scene.render_parts(pose, K, 160, 120)
    _, depth = scene.render(pose, K, 160, 120)
    labels = np.unique(parts)
    assert labels[0] == 0 and labels[-1] <= len(scene.part_names) and len(labels) > 10
    # The body stands within 0.5 m of the origin, 3 m from the camera; the floor is label 0.
    # Multisampled edges may disagree between the two passes by a pixel: allow 3 %.
    body = depth[parts > 0]
    assert np.mean((body > 2.4) & (body < 3.6)) > 0.97
    assert np.any((parts == 0) & (depth > 3.6))


@pytest.mark.parametrize("K", [np.diag([-100.0, 100.0, 1.0]), np.eye(2), np.full((3, 3), np.nan)])
def test_bad_intrinsics_raise(scene, K):
    with pytest.raises(SceneError):
        scene.render(np.eye(4), K, 64, 48)

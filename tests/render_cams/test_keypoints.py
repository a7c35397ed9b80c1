"""Keypoints: projection, depth-buffer visibility (a hand in front of the knee), rig checks."""

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.keypoints import (
    confidence,
    project_joints,
    visibility,
)
from avatarsim.render_cams.fisheye.line_of_sight import own_depth
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import (
    CameraInsideBodyError,
    camera_poses,
    check_cameras_outside,
    controller_cameras,
)
from avatarsim.render_cams.scene import BodyScene


@pytest.fixture(scope="module")
def setup():
    motion = generate("squat", duration_s=0.2, fps=30)
    scene = BodyScene(motion.skeleton)
    yield motion, scene
    scene.close()


def _looking_at(eye, target):
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = eye
    return pose


def test_hand_between_camera_and_knee_occludes_the_knee(setup):
    motion, scene = setup
    model = FisheyeModel.from_fov().scaled(0.25)
    renderer = FisheyeRenderer(scene, model, face_size=96)
    positions, rotations = motion[[0]].fk()
    joints = body17_positions(motion[[0]])
    knee = joints[0, INDEX["l_knee"]]
    camera = _looking_at(knee + [0.8, 0.15, 0.1], knee)
    depth = own_depth(scene.body, positions, rotations, camera[None, :3, 3], joints)[0]
    uv, in_image, joint_range = project_joints(model, camera[None], joints)

    scene.set_pose(positions[0], rotations[0])
    _, range_m = renderer.render(camera)
    before = visibility(uv[0], in_image[0], joint_range[0], range_m, depth)

    hand = scene.body.skeleton.index(scene.body.rig.body17["l_wrist"])
    moved = positions[0].copy()
    moved[hand] = 0.5 * (knee + camera[:3, 3])  # the hand and its controller grip
    scene.set_pose(moved, rotations[0])
    _, range_m = renderer.render(camera)
    after = visibility(uv[0], in_image[0], joint_range[0], range_m, depth)

    knee_i = INDEX["l_knee"]
    assert before[knee_i] and not after[knee_i]
    conf = confidence(model, uv[0], after)
    assert conf[knee_i] == pytest.approx(0.1) and conf[before & after].min() >= 0.5


def test_rig_cameras_ride_on_the_controllers_and_look_at_the_body(setup):
    motion, scene = setup
    cameras = controller_cameras()
    poses = camera_poses(motion, cameras)
    assert poses.shape == (motion.n_frames, 4, 4, 4)
    np.testing.assert_allclose(
        poses[..., :3, :3] @ np.swapaxes(poses[..., :3, :3], -1, -2),
        np.broadcast_to(np.eye(3), poses[..., :3, :3].shape),
        atol=1e-9,
    )
    # Each camera is within 15 cm of its controller's wrist.
    joints = body17_positions(motion)
    wrists = joints[:, [INDEX["l_wrist"]] * 2 + [INDEX["r_wrist"]] * 2]
    assert np.linalg.norm(poses[..., :3, 3] - wrists, axis=-1).max() < 0.15
    check_cameras_outside(scene.body, motion, poses)
    inside = poses.copy()
    inside[:, 0, :3, 3] = joints[:, INDEX["pelvis"]]
    with pytest.raises(CameraInsideBodyError, match="inside the body"):
        check_cameras_outside(scene.body, motion, inside)

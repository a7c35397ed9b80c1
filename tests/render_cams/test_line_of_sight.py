"""Line of sight from a camera to the body17 joints without rendering (the ray test the
keypoint datasets use), against the rendered range image."""

import numpy as np

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.line_of_sight import occluded, own_depth
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras
from avatarsim.render_cams.scene import body_for_motion


def test_a_hand_between_camera_and_knee_hides_the_knee():
    motion = generate("squat", duration_s=0.2, fps=30)
    body = body_for_motion(motion)
    positions, rotations = motion[[0]].fk()
    joints = body17_positions(motion[[0]])
    knee = joints[0, INDEX["l_knee"]]
    camera = knee + np.array([0.8, 0.15, 0.1])
    before = occluded(body, positions, rotations, camera[None], joints)[0]
    moved = positions.copy()
    hand = body.skeleton.index(body.rig.body17["l_wrist"])
    moved[0, hand] = 0.5 * (knee + camera)
    after = occluded(body, moved, rotations, camera[None], joints)[0]
    assert not before[INDEX["l_knee"]] and after[INDEX["l_knee"]]
    # The knee sits inside its own thigh and shank: the ray crosses some of them first.
    depth = own_depth(body, positions, rotations, camera[None], joints)[0]
    assert 0.03 < depth[INDEX["l_knee"]] < 0.2


def test_ray_test_agrees_with_the_range_image():
    """On the controller cameras over one second of the study and of boxing, the ray test
    and the rendered range image (:func:`render_cams.fisheye.keypoints.visibility`) agree on
    most in-image joints (measured 98 % and 86 %)."""
    for activity, seed in (("controllerpose_study", 1), ("box", 0)):
        motion = generate(activity, duration_s=1.0, fps=30, seed=seed)
        recording = FisheyeRig(bad_frame_rate=0.0, scale=0.5).sample(motion, seed)
        body = body_for_motion(motion)
        poses = camera_poses(motion, controller_cameras())
        joints, pose = body17_positions(motion), motion.fk()
        hidden = np.stack(
            [occluded(body, *pose, poses[:, c, :3, 3], joints) for c in range(4)], axis=1
        )
        shape = (motion.n_frames, 4, 17)
        rendered = np.array([r["visible"] for r in recording.records]).reshape(shape)
        in_image = np.array([r["in_image"] for r in recording.records]).reshape(shape)
        agree = ((in_image & ~hidden) == rendered)[in_image].mean()
        assert agree > 0.8, (activity, agree)

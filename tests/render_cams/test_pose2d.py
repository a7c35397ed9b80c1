"""The keypoint pipeline of a controller (ControllerPose §4.2-4.3): joints onto the composite
from the cameras the filter kept, detection, torso-normal view from the detected torso,
detection again."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.detector import ErrorModelDetector
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.keypoints import confidence, project_joints
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.pose2d import composite_keypoints, controller_pose2d
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras
from avatarsim.render_cams.fisheye.stitch import stitch_params
from avatarsim.render_cams.fisheye.torso_view import CORNER_INDICES, apply_homography
from avatarsim.sim.humanoid import humanoid_for

MODEL = FisheyeModel.from_fov().scaled(0.25)
EXACT = ErrorModelDetector(error_scale=0.0, miss_rate=0.0, swap_rate=0.0, confidence_noise=0.0)


@pytest.fixture(scope="module")
def pair():
    """A squat seen by the right controller's two cameras: exact pixels ``(T, 2, 17, 2)``,
    in-image ``(T, 2, 17)``, scores, and the pair's stitch parameters."""
    motion = generate("squat", duration_s=1.0, fps=30)
    cameras = controller_cameras(("right_controller",))
    poses = camera_poses(motion, cameras)  # (T, 2, 4, 4)
    joints = body17_positions(motion)
    n, c = poses.shape[:2]
    uv, in_image, _ = project_joints(MODEL, poses.reshape(-1, 4, 4), np.repeat(joints, c, 0))
    uv, in_image = uv.reshape(n, c, 17, 2), in_image.reshape(n, c, 17)
    return uv, in_image, confidence(MODEL, uv, in_image), stitch_params(MODEL, cameras)


def test_joints_land_on_the_composite_from_the_kept_cameras(pair):
    uv, in_image, score, params = pair
    both = np.ones(uv.shape[:2], bool)
    composite = composite_keypoints(params, uv, in_image, in_image, score, both)
    assert composite.in_image.mean() > 0.5
    # A joint seen by one camera only lands where that camera's ray meets the stitch surface.
    only_grip = in_image[:, 1] & ~in_image[:, 0]
    t, j = np.argwhere(only_grip)[0]
    np.testing.assert_allclose(composite.uv[t, j], params.to_composite(1, uv[t, 1, j]), atol=1e-9)
    # With the grip camera's frames filtered, only the ring camera's joints are there.
    ring_only = np.stack([both[:, 0], ~both[:, 1]], axis=1)
    kept = composite_keypoints(params, uv, in_image, in_image, score, ring_only)
    assert not np.any(kept.in_image & ~in_image[:, 0])
    none = composite_keypoints(params, uv, in_image, in_image, score, ~both)
    assert not none.in_image.any()


def test_torso_view_comes_from_the_detected_torso_and_is_detected_again(pair):
    uv, in_image, score, params = pair
    composite = composite_keypoints(
        params, uv, in_image, in_image, score, np.ones(uv.shape[:2], bool)
    )
    exact = controller_pose2d(params, EXACT, composite, np.random.default_rng(0))
    valid = exact.torso.valid
    assert valid.any()
    # An exact detector: the view maps the composite's exact torso onto the frontal torso,
    # and the joints detected again are the exact joints moved by the view.
    corners = exact.composite.uv[valid][:, CORNER_INDICES]
    np.testing.assert_allclose(
        apply_homography(exact.torso.H[valid], corners), exact.torso.dst[valid], atol=1e-6
    )
    found = exact.torso_detection.detected
    np.testing.assert_allclose(exact.torso_detection.uv[found], exact.torso_uv[found], atol=1e-9)
    # A noisy detector builds its view from its own (noisy) shoulders and hips.
    noisy = controller_pose2d(params, ErrorModelDetector(), composite, np.random.default_rng(1))
    ok = noisy.torso.valid
    reported = noisy.composite_detection.uv[ok][:, CORNER_INDICES]
    np.testing.assert_allclose(
        apply_homography(noisy.torso.H[ok], reported), noisy.torso.dst[ok], atol=1e-6
    )
    assert not np.allclose(noisy.torso.H[ok & valid], exact.torso.H[ok & valid])
    l_hip = INDEX["l_hip"]
    assert np.all(noisy.torso.valid <= noisy.composite_detection.detected[:, l_hip])


REAL_CLIPS = {
    "cmu": ("cmu/09_01.bvh", 0.05),  # a run; frame 0 is a T-pose
    "bandai-1": ("bandai/dataset-1/data/dataset-1_walk_normal_001.bvh", 1.0),
    "bandai-2": ("bandai/dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh", 1.0),
}
"""Source -> clip and the second a 0.4 s slice of it starts at."""


@pytest.mark.mocap
@pytest.mark.parametrize("source", sorted(REAL_CLIPS))
def test_real_clip_through_filter_detector_composite_and_torso_view(mocap_dir, source):
    rel, start_s = REAL_CLIPS[source]
    motion = load_motion(mocap_dir / rel)
    first = int(round(start_s * motion.fps))
    # The humanoid for the clip (its own rig retargeted), as the render command and datasets do.
    humanoid = humanoid_for(motion[first : first + int(0.4 * motion.fps)])
    recording = FisheyeRig(scale=0.125).sample(humanoid.motion, 0, humanoid.body)
    assert sorted(recording.views) == ["left_controller", "right_controller"]
    detected = np.array([r["detected"] for r in recording.records])
    shown = np.array([r["in_image"] for r in recording.records])
    assert detected.any() and detected.sum() <= shown.sum() + 2 * len(recording.records)
    for view in recording.views.values():
        found = view.composite_detection.detected
        assert np.all(np.isfinite(view.composite_detection.uv))
        assert np.all(view.torso.valid <= found[:, CORNER_INDICES].all(axis=1))

"""A controller camera inside or against the body: a dark, flagged frame, never a refused clip."""

from __future__ import annotations

import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.render_cams.fisheye import occlusion
from avatarsim.render_cams.fisheye.bad_frames import BLACK_LEVEL
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import (
    CameraMountError,
    Mount,
    camera_poses,
    controller_cameras,
    inside_body,
)
from avatarsim.render_cams.kinect.placement import look_at
from avatarsim.render_cams.scene import BodyScene, SceneError
from tests.render_cams.kinect_builders import t_pose

TINY = FisheyeModel.from_fov(width=80, height=60)
# The ring camera at the palm centre: inside the hand that holds the controller.
IN_THE_PALM = Mount(ring_offset_m=(0.0, 0.0, 0.0))


def test_the_palm_mount_puts_the_ring_cameras_inside_the_hand():
    motion = t_pose(3)
    poses = camera_poses(motion, controller_cameras(mount=IN_THE_PALM))
    inside = inside_body(build_body(motion.skeleton), *motion.fk(), poses[..., :3, 3])
    # Cameras: left ring, left grip, right ring, right grip.
    assert inside[:, [0, 2]].all() and not inside[:, [1, 3]].any()


def test_camera_inside_the_body_records_a_dark_flagged_frame():
    motion = t_pose(3)
    rig = FisheyeRig(model=TINY, mount=IN_THE_PALM, bad_frame_rate=0.0)
    recording = rig.sample(motion)  # not refused
    assert recording.summary["frames"] == 3
    assert recording.summary["occluded_frames"] == {
        "left_controller-ring": 3,
        "left_controller-grip": 0,
        "right_controller-ring": 3,
        "right_controller-grip": 0,
    }
    for record in recording.records:
        ring = record["camera"].endswith("ring")
        assert record["occluded"] == ring
        if ring:
            assert record["lens_blocked"] == 1.0
            assert record["mean_luminance"] < BLACK_LEVEL  # near-black: a covered lens
            assert not any(record["visible"]) and max(record["confidence"]) < 0.5
        else:
            assert record["lens_blocked"] < occlusion.OCCLUDED_FRACTION
            assert record["mean_luminance"] > 2 * BLACK_LEVEL
    image, range_mm = recording.images[0, 1], recording.range_mm[0, 1]  # left ring, frame 1
    assert image.mean() < BLACK_LEVEL and not range_mm.any()  # nothing to measure


def test_lens_against_the_chest_is_blocked_and_dark():
    motion = t_pose(1)
    chest = body17_positions(motion)[0, INDEX["neck"]] - [0.0, 0.0, 0.15]
    with BodyScene(motion.skeleton) as scene:
        scene.update(motion, 0)
        renderer = FisheyeRenderer(scene, TINY)
        circle = renderer.maps.range_scale > 0
        # The skin of the chest is about 2 cm in front of the camera: a lens pressed to it.
        probe = look_at(chest + [0.3, 0.0, 0.0], chest)
        _, range_probe = renderer.render(probe)
        surface = chest[0] + 0.3 - range_probe[TINY.height // 2, TINY.width // 2]
        against = look_at(chest + [surface - chest[0] + 0.02, 0.0, 0.0], chest)
        colour, range_m = renderer.render(against)
        dark, blocked = occlusion.block_lens(colour, range_m, circle)
        far = look_at(chest + [1.0, 0.0, 0.0], chest)
        colour_far, range_far = renderer.render(far)
        _, blocked_far = occlusion.block_lens(colour_far, range_far, circle)
    assert blocked >= occlusion.OCCLUDED_FRACTION and blocked_far == 0.0
    near = circle & (range_m > 0) & (range_m < occlusion.BLOCKING_RANGE_M)
    assert occlusion.mean_luminance(dark, near) < 0.5 * occlusion.mean_luminance(colour, near)
    assert occlusion.mean_luminance(dark, circle) < occlusion.mean_luminance(colour, circle)


def test_bad_mounts_and_mismatched_bodies_are_typed_errors():
    with pytest.raises(CameraMountError, match="within"):
        Mount(ring_offset_m=(0.5, 0.0, 0.0))
    with pytest.raises(CameraMountError, match="pitch"):
        Mount(grip_pitch_rad=2.0)
    cmu_body = build_body(load_rig("cmu").skeleton)  # not the t-pose motion's rig
    with pytest.raises(SceneError, match="retarget"):
        FisheyeRig(model=TINY).sample(t_pose(2), body=cmu_body)

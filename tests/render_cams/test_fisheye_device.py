"""FisheyeRig: a Device whose recording (images, range, records) stays in memory."""

import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import ACTIVITIES, Subject, generate
from avatarsim.render_cams.device import Device, DeviceError, motion_at_rate
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.rig import (
    camera_poses,
    check_cameras_outside,
    controller_cameras,
)


def test_a_rig_is_a_device_that_records_every_camera_in_memory():
    rig = FisheyeRig(scale=0.125)
    assert isinstance(rig, Device) and rig.rate_hz == 30.0
    motion = generate("wave", duration_s=0.3, fps=90)  # resampled to the cameras' 30 Hz
    recording = rig.sample(motion, seed=5)
    assert recording.images.shape == (4, 10, 60, 80, 3) and recording.images.dtype == np.uint8
    assert recording.range_mm.shape == (4, 10, 60, 80) and recording.range_mm.dtype == np.uint16
    assert len(recording.records) == 40 and recording.summary["seed"] == 5
    assert recording.records[5]["camera"] == recording.names[1]  # frame 1, second camera
    # The range is in millimetres: the body is a few tens of centimetres to metres away.
    hits = recording.range_mm[recording.range_mm > 0]
    assert 50 < np.median(hits) < 5000


@pytest.mark.parametrize("scale", [0.0, 10.0, float("nan")])
def test_a_scale_outside_its_range_is_refused(scale):
    with pytest.raises(DeviceError, match="scale"):
        FisheyeRig(scale=scale)


@pytest.mark.parametrize("activity", ACTIVITIES)
def test_default_cameras_stay_outside_the_body_in_every_activity(activity):
    # Short and tall subjects and several takes, 4 s each: the boxing guard holds the grip
    # camera against the chest, a short runner's arm swing brings it to the hip.
    for seed, subject in ((0, Subject()), (1, Subject(height_m=1.55)), (2, Subject(height_m=1.95))):
        motion = motion_at_rate(generate(activity, subject, 4.0, seed=seed), 30.0)
        poses = camera_poses(motion, controller_cameras())
        check_cameras_outside(build_body(motion.skeleton), motion, poses)


@pytest.mark.parametrize("activity", ACTIVITIES)
def test_every_activity_renders_with_the_default_cameras(tmp_path, activity):
    # 0.6-0.9 s of a 2 s take: the window where the boxing guard first put a camera inside.
    motion = generate(activity, duration_s=2.0, fps=30)[18:28]
    tiny = FisheyeModel.from_fov(width=64, height=48)
    recording = FisheyeRig(model=tiny).sample(motion)
    assert recording.summary["frames"] == 10

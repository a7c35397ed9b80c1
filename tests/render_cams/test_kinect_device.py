"""Kinect: a Device whose recording (depth, body index, skeleton) stays in memory."""

from __future__ import annotations

import numpy as np
import pytest

from render_cams.device import Device
from render_cams.kinect.depth import BODY_INDEX_NONE
from render_cams.kinect.device import Kinect
from render_cams.kinect.placement import performer_distance
from render_cams.kinect.sensors import KinectError
from tests.render_cams.kinect_builders import t_pose


def test_a_kinect_is_a_device_that_records_depth_body_index_and_skeleton():
    kinect = Kinect("kinect-v2", max_frames=2)
    assert isinstance(kinect, Device) and kinect.name == "kinect-v2" and kinect.rate_hz == 30.0
    motion = t_pose(4, fps=30.0)
    recording = kinect.sample(motion, seed=3)
    # Kinect V2 depth is 512 x 424 (Microsoft's published depth mode).
    assert recording.depth_mm.shape == (2, 424, 512) and recording.depth_mm.dtype == np.uint16
    assert recording.body_index.shape == (2, 424, 512)
    assert recording.skeleton.positions.shape == (2, 25, 3)  # the V2 SDK's 25 joints
    body = recording.body_index[1] == 0
    assert set(np.unique(recording.body_index)) == {0, BODY_INDEX_NONE}
    placed = performer_distance(recording.camera_to_world, motion)[1]
    assert abs(np.median(recording.depth_mm[1][body]) / 1e3 - placed) < 0.3
    assert recording.record["seed"] == 3 and recording.record["frames"] == 2


def test_same_seed_same_recording_and_bad_options_are_refused():
    kinect = Kinect("azure-kinect", max_frames=1)
    first, second = (kinect.sample(t_pose(2), seed=7) for _ in range(2))
    assert np.array_equal(first.depth_mm, second.depth_mm)
    with pytest.raises(KinectError, match="max_frames"):
        Kinect(max_frames=0)

"""Kinect: a Device whose recording (depth, body index, skeleton) stays in memory."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.render_cams.device import Device
from avatarsim.render_cams.kinect.depth import BODY_INDEX_NONE
from avatarsim.render_cams.kinect.device import Kinect
from avatarsim.render_cams.kinect.placement import performer_distance
from avatarsim.render_cams.kinect.sensors import KinectError
from tests.render_cams.kinect_builders import t_pose


def test_a_kinect_is_a_device_that_records_depth_body_index_and_skeleton():
    kinect = Kinect("kinect-v2", max_frames=2)
    assert isinstance(kinect, Device) and kinect.name == "kinect-v2" and kinect.rate_hz == 30.0
    motion = t_pose(4, fps=30.0)
    recording = kinect.sample(motion, seed=3)
    depth_mm, body_index, _ = recording.frames.stack()
    # Kinect V2 depth is 512 x 424 (Microsoft's published depth mode).
    assert depth_mm.shape == (2, 424, 512) and depth_mm.dtype == np.uint16
    assert body_index.shape == (2, 424, 512) and len(recording.frames) == 2
    assert recording.skeleton.positions.shape == (2, 25, 3)  # the V2 SDK's 25 joints
    assert set(np.unique(body_index)) == {0, BODY_INDEX_NONE}
    placed = performer_distance(recording.camera_to_world, motion)[1]
    assert abs(np.median(depth_mm[1][body_index[1] == 0]) / 1e3 - placed) < 0.3
    assert recording.record["seed"] == 3 and recording.record["frames"] == 2


def test_every_pass_over_the_frames_gives_the_same_frames_and_bad_options_are_refused():
    frames = Kinect("azure-kinect", max_frames=1).sample(t_pose(2), seed=7).frames
    first, again = frames.stack(), frames.stack()
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[1], again[1])
    with pytest.raises(KinectError, match="max_frames"):
        Kinect(max_frames=0)

"""A recorded Kinect sequence on disk: files, formats, determinism."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from avatarsim.render_cams.kinect import KinectError, TrackingState
from avatarsim.render_cams.kinect.depth import BODY_INDEX_NONE, read_depth_png
from avatarsim.render_cams.kinect.device import Kinect
from avatarsim.render_cams.kinect.placement import performer_distance
from avatarsim.render_cams.kinect.sequence import read_kinect_skeleton, write_kinect_recording
from tests.render_cams.builders import folder_bytes
from tests.render_cams.kinect_builders import t_pose


def test_sequence_writes_depth_body_index_skeleton_and_preview(tmp_path):
    motion = t_pose(4, fps=30.0)
    kinect = Kinect("azure-kinect", max_frames=3)
    record = write_kinect_recording(kinect.sample(motion, seed=5), tmp_path / "a")
    again = write_kinect_recording(kinect.sample(motion, seed=5), tmp_path / "b")
    assert record["frames"] == 3 and record["seed"] == 5
    depth = read_depth_png(tmp_path / "a" / "depth" / "000002.png")
    assert depth.shape == (576, 640) and depth.dtype == np.uint16
    body_index = cv2.imread(str(tmp_path / "a" / "body_index" / "000002.png"), -1)
    # The sensor was set up for the take: the body is at the distance it was placed at.
    placed = performer_distance(np.array(record["camera_to_world"]), motion)[2]
    assert abs(np.median(depth[body_index == 0]) / 1e3 - placed) < 0.3
    assert set(np.unique(body_index)) == {0, BODY_INDEX_NONE}
    frame = json.loads((tmp_path / "a" / "skeleton" / "000002.json").read_text())
    assert len(frame["joints"]) == 32
    assert (tmp_path / "a" / "preview.mp4").stat().st_size > 1000
    assert folder_bytes(tmp_path / "a") == folder_bytes(tmp_path / "b")  # incl. the preview
    assert json.loads((tmp_path / "a" / "recording.json").read_text())["device"] == "azure-kinect"
    assert again == record
    # The skeleton stream reads back (MoveBox plays recorded takes); NotTracked joints have
    # no position on disk and come back NaN.
    stream = kinect.sample(motion, seed=5).skeleton
    back = read_kinect_skeleton(tmp_path / "a")
    assert back.joint_names == stream.joint_names and np.array_equal(back.states, stream.states)
    seen = stream.states != TrackingState.NOT_TRACKED
    assert np.allclose(back.positions[seen], stream.positions[seen], atol=1e-5)
    assert np.isnan(back.positions[~seen]).all()


def test_reading_a_folder_without_frames_raises(tmp_path):
    with pytest.raises(KinectError, match="no Kinect skeleton frames"):
        read_kinect_skeleton(tmp_path)

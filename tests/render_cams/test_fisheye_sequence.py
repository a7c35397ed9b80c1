"""render_fisheye_sequence: files, self-describing records that re-project with OpenCV."""

import json

import cv2
import numpy as np
import pytest

from avatar_models.body import build_body
from avatar_models.generator import ACTIVITIES, Subject, generate
from render_cams.device import motion_at_rate
from render_cams.fisheye.model import FisheyeModel
from render_cams.fisheye.records import model_from_record
from render_cams.fisheye.rig import camera_poses, check_cameras_outside, controller_cameras
from render_cams.fisheye.sequence import render_fisheye_sequence
from tests.render_cams.builders import folder_bytes


def test_sequence_files_and_records_reproject_with_opencv(tmp_path):
    motion = generate("wave", duration_s=0.3, fps=30)
    summary = render_fisheye_sequence(motion, tmp_path, seed=5, scale=0.125)
    assert summary["frames"] == 10 and len(summary["cameras"]) == 4
    assert (tmp_path / "fisheye.mp4").stat().st_size > 0
    image = cv2.imread(str(tmp_path / summary["cameras"][0] / "000003.png"))
    range_mm = cv2.imread(str(tmp_path / summary["cameras"][0] / "000003_range.png"), -1)
    assert image.shape == (60, 80, 3) and range_mm.dtype == np.uint16
    # One stitched composite per controller and frame (two cameras -> one cylinder).
    assert summary["stitched"] == ["stitched/left_controller", "stitched/right_controller"]
    composites = sorted((tmp_path / "stitched" / "left_controller").glob("*.png"))
    assert len(composites) == 10 and cv2.imread(str(composites[0])).mean() > 0
    data = json.loads((tmp_path / "keypoints.json").read_text())
    assert data["seed"] == 5 and len(data["records"]) == 40
    record = data["records"][7]
    model = model_from_record(record)
    w2c = np.array(record["world_to_camera"])
    rvec, _ = cv2.Rodrigues(w2c[:3, :3])
    joints = np.array(record["joints_world"])[:, None]
    uv, _ = cv2.fisheye.projectPoints(joints, rvec, w2c[:3, 3], model.K, model.D)
    shown = np.array(record["in_image"])
    assert shown.any()
    np.testing.assert_allclose(uv[shown, 0], np.array(record["keypoints_px"])[shown], atol=1e-3)


def test_same_seed_gives_the_same_bytes_in_any_folder(tmp_path):
    motion = generate("wave", duration_s=0.2, fps=30)
    first = render_fisheye_sequence(motion, tmp_path / "a", seed=3, scale=0.1)
    second = render_fisheye_sequence(motion, tmp_path / "nested" / "b", seed=3, scale=0.1)
    files = folder_bytes(tmp_path / "a")
    assert "keypoints.json" in files and "fisheye.mp4" in files
    assert files == folder_bytes(tmp_path / "nested" / "b")
    assert first["out_dir"] != second["out_dir"] and first["fps_rendered"] > 0  # summary only


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
    summary = render_fisheye_sequence(motion, tmp_path, model=tiny, video=False)
    assert summary["frames"] == 10

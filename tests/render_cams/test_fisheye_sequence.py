"""write_fisheye_recording: files, self-describing records that re-project with OpenCV."""

import json

import cv2
import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.records import model_from_record
from avatarsim.render_cams.fisheye.sequence import write_fisheye_recording
from tests.render_cams.builders import folder_bytes


def test_sequence_files_and_records_reproject_with_opencv(tmp_path):
    motion = generate("wave", duration_s=0.3, fps=30)
    summary = write_fisheye_recording(FisheyeRig(scale=0.125).sample(motion, 5), tmp_path)
    assert summary["frames"] == 10 and len(summary["cameras"]) == 4
    assert (tmp_path / "fisheye.mp4").stat().st_size > 0
    image = cv2.imread(str(tmp_path / summary["cameras"][0] / "000003.png"))
    range_mm = cv2.imread(str(tmp_path / summary["cameras"][0] / "000003_range.png"), -1)
    assert image.shape == (60, 80, 3) and range_mm.dtype == np.uint16
    # One stitched composite per controller and frame (two cameras -> one cylinder).
    assert summary["stitched"] == ["stitched/left_controller", "stitched/right_controller"]
    composites = sorted((tmp_path / "stitched" / "left_controller").glob("*.png"))
    assert len(composites) == 10 and cv2.imread(str(composites[0])).mean() > 0
    # The detector's keypoints on each composite and its torso-normal view, every frame.
    views = json.loads((tmp_path / "views.json").read_text())
    assert sorted(views) == ["left_controller", "right_controller"]
    frame = views["left_controller"][3]
    assert len(frame["composite"]["detected_px"]) == 17 and len(frame["torso"]["H"]) == 3
    torso_files = len(list((tmp_path / "torso" / "left_controller").glob("*.png")))
    assert torso_files == sum(f["torso"]["valid"] for f in views["left_controller"])
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
    rig = FisheyeRig(scale=0.1)
    first = write_fisheye_recording(rig.sample(motion, 3), tmp_path / "a")
    second = write_fisheye_recording(rig.sample(motion, 3), tmp_path / "nested" / "b")
    files = folder_bytes(tmp_path / "a")
    assert "keypoints.json" in files and "fisheye.mp4" in files
    assert files == folder_bytes(tmp_path / "nested" / "b")
    assert first["out_dir"] != second["out_dir"] and first["fps_rendered"] > 0  # summary only

"""Simulated checkerboard calibration of the fisheye (ControllerPose §4.2) against the truth."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.render_cams.fisheye import calibration
from avatarsim.render_cams.fisheye.calibration import CalibrationError, calibrate_fisheye
from avatarsim.render_cams.fisheye.model import FisheyeModel

# A paper-sized lens (640x480, 150 x 120 deg) with non-zero Kannala-Brandt coefficients.
TRUTH = FisheyeModel.from_fov(D=(0.02, -0.01, 0.003, -0.0005))


@pytest.fixture(scope="module")
def result():
    return calibrate_fisheye(TRUTH, n_views=15, seed=0)


def test_recovers_intrinsics(result):
    err = result.errors
    assert abs(err["fx_rel"]) < 0.01 and abs(err["fy_rel"]) < 0.01
    assert abs(err["cx_px"]) < 2.0 and abs(err["cy_px"]) < 2.0
    assert result.rms_px < 0.5
    assert np.max(err["D_abs"]) < 0.01
    assert result.n_views == 15


def test_recovered_model_reprojects_like_the_truth(result):
    # Rays up to 70 deg off axis land on (nearly) the same pixels through both models.
    theta = np.radians(np.linspace(0.0, 70.0, 15))
    azimuth = np.linspace(0.0, 2.0 * np.pi, 15)
    t, a = np.meshgrid(theta, azimuth)
    rays = np.stack([np.sin(t) * np.cos(a), np.sin(t) * np.sin(a), np.cos(t)], axis=-1)
    true_uv, ok = TRUTH.project(rays)
    uv, _ = result.model.project(rays)
    assert np.max(np.linalg.norm(uv - true_uv, axis=-1)[ok]) < 1.0


def test_detected_corners_match_projection():
    rng = np.random.default_rng(3)
    model = TRUTH.scaled(0.5)  # smaller image: faster, same geometry
    rays = calibration.supersampled_rays(model)
    errors = []
    for _ in range(3):
        pose = calibration.random_board_pose(model, rng)
        corners_cam = calibration.board_corners() @ pose[:3, :3].T + pose[:3, 3]
        expected, in_image = model.project(corners_cam)
        assert np.all(in_image)
        found = calibration.detect_corners(calibration.render_board(rays, pose), expected)
        if found is not None:
            errors.append(np.linalg.norm(found - expected, axis=1))
    assert errors, "no board detected"
    errors = np.concatenate(errors)
    assert np.median(errors) < 0.1 and np.max(errors) < 0.5


def test_rendered_board_squares_where_expected():
    model = TRUTH.scaled(0.25)  # 160x120, principal point (79.5, 59.5)
    pose = np.eye(4)  # board axes along the camera's: board +x right, +y down
    pose[:3, 3] = [-5 * calibration.SQUARE_M, -3 * calibration.SQUARE_M, 0.3]
    image = calibration.render_board(calibration.supersampled_rays(model), pose)
    # The inner corner between squares (4..5, 2..3) is on the optical axis; 2.5 px either side
    # (about 1.2 cm) lies inside those squares: black where column + row is even.
    assert image[57, 77] == 0 and image[62, 82] == 0
    assert image[57, 82] == 255 and image[62, 77] == 255
    assert image[0, 0] == round(255 * calibration.BACKGROUND)


def test_too_few_views_is_an_error():
    with pytest.raises(CalibrationError):
        calibrate_fisheye(TRUTH, n_views=2)

"""Depth noise model on analytic planes: statistics, lateral jitter, flying pixels, range."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.stats import norm

from avatarsim.avatar_models import AvatarsimError
from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.kinect import DepthNoiseModel, KinectError, get_sensor
from avatarsim.render_cams.kinect.noise import incidence_angles
from avatarsim.render_cams.tracking import UnknownDeviceError

SENSOR = get_sensor("kinect-v2")
K = SENSOR.K
AXIAL_ONLY = DepthNoiseModel(lateral_px=(0.0, 0.0), flying_probability=0.0)


def plane_depth(distance_m: float, tilt_rad: float, shape=(SENSOR.height, SENSOR.width)):
    """Depth of a plane through (0, 0, distance) whose normal is tilted by ``tilt`` from the
    optical axis about the camera x axis, and each pixel's true incidence angle."""
    h, w = shape
    v, u = np.mgrid[0:h, 0:w]
    rays = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones((h, w))], -1)
    normal = np.array([0.0, np.sin(tilt_rad), -np.cos(tilt_rad)])
    depth = distance_m * normal[2] / (rays @ normal)
    angle = np.arccos(np.abs(rays @ normal) / np.linalg.norm(rays, axis=-1))
    return depth, angle


def test_incidence_angles_of_a_tilted_plane():
    depth, angle = plane_depth(2.0, np.radians(50.0))
    assert np.max(np.abs(incidence_angles(depth, K) - angle)) < np.radians(0.2)


@pytest.mark.parametrize(
    ("distance", "tilt_deg", "sigma_mm"),
    # Fankhauser et al. 2015 by hand: 1.5 - 0.5 z + 0.3 z^2 + 0.1 z^1.5 t^2 / (pi/2 - t)^2
    [(1.0, 0.0, 1.3), (3.0, 0.0, 2.7), (1.0, 45.0, 1.4), (3.0, 45.0, 2.7 + 0.1 * 3**1.5)],
)
def test_axial_noise_statistics_match_the_published_model(distance, tilt_deg, sigma_mm):
    depth, angle = plane_depth(distance, np.radians(tilt_deg))
    # Pixels within 1 % of the distance and 1 degree of the tilt: sigma is that of the table.
    centre = (np.abs(depth / distance - 1.0) < 0.01) & (np.abs(angle - np.radians(tilt_deg)) < 0.02)
    rng = np.random.default_rng(0)
    residuals = np.concatenate(
        [(AXIAL_ONLY.apply(depth, K, SENSOR.range_m, rng)[0] - depth)[centre] for _ in range(30)]
    )
    assert residuals.size > 4000
    assert abs(residuals.std() * 1e3 / sigma_mm - 1.0) < 0.04
    assert abs(residuals.mean()) * 1e3 < 4 * sigma_mm / np.sqrt(residuals.size)


def test_lateral_noise_moves_edges_by_the_modelled_pixel_sigma():
    depth = np.full((SENSOR.height, SENSOR.width), 2.0)
    depth[:, 256:] = 2.05  # a small step: no flying pixels, only lateral jitter crosses it
    model = DepthNoiseModel(flying_probability=0.0)
    rng = np.random.default_rng(1)
    crossed = np.concatenate(
        [model.apply(depth, K, SENSOR.range_m, rng)[0][:, 255] > 2.025 for _ in range(20)]
    )
    # Nearest-pixel sampling crosses when the jitter exceeds half a pixel; sigma_L(0) = 0.8 px.
    assert crossed.mean() == pytest.approx(norm.sf(0.5 / 0.8), abs=0.02)


def test_flying_pixels_only_at_depth_edges():
    depth = np.full((SENSOR.height, SENSOR.width), 3.5)
    depth[100:300, 200:330] = 2.0  # a box in front of a wall
    model = SENSOR.noise
    rng = np.random.default_rng(2)
    noisy, _ = model.apply(depth, K, SENSOR.range_m, rng)
    off_both = np.minimum(np.abs(noisy - 2.0), np.abs(noisy - 3.5))
    flying = (noisy > 0) & (off_both > 6 * model.axial_sigma_m(3.5, 0.0))
    rows, cols = np.nonzero(flying)
    # Lateral jitter (sigma 0.8 px) can carry an edge pixel up to a few pixels away.
    near_row_edge = (np.abs(rows - 99.5) < 5) | (np.abs(rows - 299.5) < 5)
    near_col_edge = (np.abs(cols - 199.5) < 5) | (np.abs(cols - 329.5) < 5)
    inside_span = (rows > 94) & (rows < 305) & (cols > 194) & (cols < 335)
    assert flying.sum() > 100
    assert np.all(inside_span & (near_row_edge | near_col_edge))


def test_out_of_range_and_grazing_pixels_are_invalid():
    rng = np.random.default_rng(3)
    for distance in (0.3, 5.0):
        assert not np.any(SENSOR.noise.apply(plane_depth(distance, 0.0)[0], K, (0.5, 4.5), rng)[0])
    grazing, _ = plane_depth(2.0, np.radians(85.0))
    noisy, _ = SENSOR.noise.apply(np.where(grazing > 0, grazing, 0.0), K, (0.5, 4.5), rng)
    assert (noisy[200:224, 240:272] == 0).all()
    assert (noisy[np.zeros_like(noisy, bool)] == 0).all()
    assert SENSOR.noise.apply(np.zeros((4, 4)), K, (0.5, 4.5), rng)[0].sum() == 0


def test_bad_sensor_and_noise_settings_raise_typed_errors():
    with pytest.raises(UnknownDeviceError, match="kinect-v3"):
        get_sensor("kinect-v3")
    with pytest.raises(KinectError, match="near < far"):
        dataclasses.replace(SENSOR, range_m=(-1.0, 4.5))
    with pytest.raises(KinectError, match="near < far"):
        dataclasses.replace(SENSOR, range_m=(3.0, 1.0))
    with pytest.raises(DeviceError, match="flying_probability"):
        DepthNoiseModel(flying_probability=1.5)
    assert issubclass(KinectError, AvatarsimError) and issubclass(
        UnknownDeviceError, AvatarsimError
    )


def test_sensor_specs():
    v2, azure = get_sensor("kinect-v2"), get_sensor("azure-kinect")
    assert (v2.width, v2.height, v2.range_m) == (512, 424, (0.5, 4.5))
    assert (azure.width, azure.height, azure.range_m) == (640, 576, (0.5, 3.86))
    for sensor in (v2, azure, get_sensor("azure-kinect-wfov-binned")):
        h_fov = 2 * np.degrees(np.arctan(sensor.width / 2 / sensor.K[0, 0]))
        v_fov = 2 * np.degrees(np.arctan(sensor.height / 2 / sensor.K[1, 1]))
        assert h_fov == pytest.approx(sensor.fov_deg[0])
        assert v_fov == pytest.approx(sensor.fov_deg[1])

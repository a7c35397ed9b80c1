"""Torso-normal-aligned views from 2D shoulder and hip keypoints (ControllerPose §4.3),
checked against pinhole projections of a planar torso."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.render_cams.fisheye.torso_view import (
    TORSO_CORNERS,
    TorsoViewError,
    apply_homography,
    signed_area,
    torso_view,
)

K = np.array([[300.0, 0, 320.0], [0, 300.0, 240.0], [0, 0, 1]])
# The avatar rig's rest torso (metres): shoulder joints 0.453 apart, hips 0.182, 0.504 between.
SHOULDER_W, HIP_W, TORSO_H = 0.453, 0.182, 0.504


def pinhole(points: np.ndarray) -> np.ndarray:
    p = points @ K.T
    return p[..., :2] / p[..., 2:]


def torso_joints(rotation: np.ndarray, centre) -> np.ndarray:
    """``(17, 3)`` camera-frame body17 joints of a planar torso facing the camera (chest
    towards -z, up -y) turned by ``rotation`` about its centre; limbs at the centre."""
    local = {
        "l_shoulder": [SHOULDER_W / 2, -TORSO_H / 2, 0],
        "r_shoulder": [-SHOULDER_W / 2, -TORSO_H / 2, 0],
        "l_hip": [HIP_W / 2, TORSO_H / 2, 0],
        "r_hip": [-HIP_W / 2, TORSO_H / 2, 0],
        "neck": [0, -TORSO_H / 2, 0],
        "pelvis": [0, TORSO_H / 2, 0],
    }
    joints = np.zeros((len(BODY17), 3))
    for name, p in local.items():
        joints[INDEX[name]] = p
    return joints @ rotation.T + np.asarray(centre, float)


def test_a_torso_facing_the_camera_gives_the_identity():
    # Also turned in the image plane (about the optical axis): no rotation is added.
    for roll in (0.0, 25.0):
        rotation = Rotation.from_euler("z", roll, degrees=True).as_matrix()
        view = torso_view(pinhole(torso_joints(rotation, [0.3, -0.1, 1.5])))
        assert view.valid and np.allclose(view.H, np.eye(3), atol=1e-6)


def test_an_oblique_torso_is_seen_from_the_front():
    rotation = Rotation.from_euler("yx", [40.0, -25.0], degrees=True).as_matrix()
    joints = torso_joints(rotation, [0.2, 0.15, 1.2])
    uv = pinhole(joints)
    view = torso_view(uv)
    corners = [INDEX[n] for n in TORSO_CORNERS]
    np.testing.assert_allclose(apply_homography(view.H, uv[corners]), view.dst, atol=1e-6)
    np.testing.assert_allclose(
        cv2.perspectiveTransform(uv[corners].reshape(-1, 1, 2), view.H).reshape(-1, 2),
        view.dst,
        atol=1e-6,
    )
    # In the view the torso has its true proportions: a symmetric trapezoid.
    ls, rs, rh, lh = view.dst
    assert np.linalg.norm(rh - lh) / np.linalg.norm(rs - ls) == pytest.approx(
        HIP_W / SHOULDER_W, rel=0.02
    )
    mid_top, mid_bottom = 0.5 * (ls + rs), 0.5 * (lh + rh)
    height = np.linalg.norm(mid_top - mid_bottom)
    assert height / np.linalg.norm(rs - ls) == pytest.approx(TORSO_H / SHOULDER_W, rel=0.02)
    assert abs((rs - ls) @ (mid_top - mid_bottom)) < 1e-6 * height**2
    # A point of the torso plane lands where the frontal view has it: the neck (the 3D
    # midpoint of the shoulders, not the midpoint of their images) on the shoulder line's
    # middle, the torso's 3D centre in the trapezoid's middle.
    neck = apply_homography(view.H, uv[[INDEX["neck"]]])[0]
    assert np.linalg.norm(pinhole(joints[INDEX["neck"]]) - 0.5 * (uv[3] + uv[6])) > 1.0
    assert np.linalg.norm(neck - mid_top) < 0.02 * height
    centre = apply_homography(view.H, pinhole(np.array([[0.2, 0.15, 1.2]])))[0]
    assert np.linalg.norm(centre - 0.5 * (mid_top + mid_bottom)) < 0.02 * height


def test_a_torso_seen_from_behind_stays_mirrored():
    rotation = Rotation.from_euler("y", 160.0, degrees=True).as_matrix()
    uv = pinhole(torso_joints(rotation, [0.0, 0.0, 1.4]))
    view = torso_view(uv)
    corners = [INDEX[n] for n in TORSO_CORNERS]
    assert view.valid and np.sign(signed_area(view.dst)) == np.sign(signed_area(uv[corners]))


def test_views_are_batched_and_need_all_four_corners():
    rotations = Rotation.from_euler("y", [[0.0], [30.0], [-50.0]], degrees=True).as_matrix()
    uv = np.stack([pinhole(torso_joints(r, [0.0, 0.1, 1.3])) for r in rotations])
    detected = np.ones((3, 17), bool)
    detected[2, INDEX["l_hip"]] = False
    views = torso_view(uv, detected)
    assert views.H.shape == (3, 3, 3) and views.valid.tolist() == [True, True, False]
    np.testing.assert_allclose(views.H[1], torso_view(uv[1]).H)
    np.testing.assert_allclose(views.H[2], np.eye(3))
    crossed = uv[1].copy()
    crossed[[INDEX["l_hip"], INDEX["r_hip"]]] = crossed[[INDEX["r_hip"], INDEX["l_hip"]]]
    assert not torso_view(crossed).valid  # a bow-tie, not a torso
    with pytest.raises(TorsoViewError):
        torso_view(crossed).warp(np.zeros((480, 640), np.float32))


def test_warped_view_moves_image_content_with_the_transform():
    rotation = Rotation.from_euler("y", 35.0, degrees=True).as_matrix()
    uv = pinhole(torso_joints(rotation, [0.0, 0.0, 1.3]))
    view = torso_view(uv)
    image = np.zeros((480, 640), np.float32)
    src = np.round(uv[INDEX["l_shoulder"]]).astype(int)
    image[src[1] - 2 : src[1] + 3, src[0] - 2 : src[0] + 3] = 1.0
    expected = apply_homography(view.H, src[None].astype(float))[0]
    warped = view.warp(image)
    v, u = np.mgrid[0:480, 0:640]
    got = np.array([(u * warped).sum(), (v * warped).sum()]) / warped.sum()
    assert np.linalg.norm(got - expected) < 0.5

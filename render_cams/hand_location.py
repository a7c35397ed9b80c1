"""ControllerPose §3 hand-location study, over a motion library.

The paper recorded 55 min of VR play (Beat Saber, Superhot, Pistol Whip) with a Kinect and
found the hands "operating in front of the user" 68.3 % of the time (the rest held to the
chest or resting by the side), and a mean Euclidean distance from hand (camera) to the body
centre line of 43.0 cm (SD 15.6). Here, per frame and hand:

- *in front*: the wrist is more than ``front_threshold_m`` ahead of the body centre line
  along the torso's horizontal forward axis (normal of the shoulder line); 20 cm clears the
  chest (torso radius about 12 cm) and a hand held to it;
- *camera-to-body distance*: the wrist's distance to the centre line, the segment from the
  pelvis to the neck.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.rigs import body17_positions

PAPER_IN_FRONT_SHARE = 0.683  # ControllerPose §3
PAPER_CAMERA_TO_BODY_M = 0.430  # ControllerPose §3
FRONT_THRESHOLD_M = 0.20


def hand_measures(joints: np.ndarray, front_threshold_m: float = FRONT_THRESHOLD_M):
    """``(T, 2)`` bool in front and ``(T, 2)`` distance to the centre line (m) of the left
    and right wrists, from body17 joints ``(T, 17, 3)``."""
    pelvis, neck = joints[:, INDEX["pelvis"]], joints[:, INDEX["neck"]]
    across = joints[:, INDEX["l_shoulder"]] - joints[:, INDEX["r_shoulder"]]
    forward = np.cross(across, [0.0, 0.0, 1.0])  # left x up = forward
    forward /= np.linalg.norm(forward, axis=-1, keepdims=True)
    hands = joints[:, [INDEX["l_wrist"], INDEX["r_wrist"]]]  # (T, 2, 3)
    axis = neck - pelvis
    along = (
        np.einsum("tha,ta->th", hands - pelvis[:, None], axis)
        / np.einsum("ta,ta->t", axis, axis)[:, None]
    )
    nearest = pelvis[:, None] + np.clip(along, 0.0, 1.0)[..., None] * axis[:, None]
    offset = hands - nearest
    ahead = np.einsum("tha,ta->th", offset, forward)
    return ahead > front_threshold_m, np.linalg.norm(offset, axis=-1)


def hand_location_study(
    motions: Iterable[Motion], front_threshold_m: float = FRONT_THRESHOLD_M
) -> dict:
    """Share of hand-time in front of the body and mean camera-to-body distance over
    ``motions`` (each weighted by its duration), next to the paper's values."""
    in_front, distance, weights = [], [], []
    for motion in motions:
        front, dist = hand_measures(body17_positions(motion), front_threshold_m)
        in_front.append(front.mean())
        distance.append(dist.mean())
        weights.append(motion.duration_s)
    w = np.asarray(weights) / np.sum(weights)
    return {
        "motions": len(weights),
        "in_front_share": float(np.dot(w, in_front)),
        "camera_to_body_cm": float(100.0 * np.dot(w, distance)),
        "paper_in_front_share": PAPER_IN_FRONT_SHARE,
        "paper_camera_to_body_cm": 100.0 * PAPER_CAMERA_TO_BODY_M,
        "front_threshold_m": front_threshold_m,
    }

"""Self-describing per-frame camera records (ARCHITECTURE "Outputs"): enough to re-project
with OpenCV alone: camera model name, image size, K, D, the world-to-camera 4x4, the body17
joints in world coordinates and their 2D keypoints with visibility and confidence."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.render_cams.fisheye.model import FisheyeModel


def frame_record(
    camera: str,
    model: FisheyeModel,
    frame: int,
    time_s: float,
    world_to_camera: np.ndarray,
    joints_world: np.ndarray,
    uv: np.ndarray,
    in_image: np.ndarray,
    visible: np.ndarray,
    conf: np.ndarray,
    bad_frame: bool = False,
    lens_blocked: float = 0.0,
    occluded: bool = False,
    mean_luminance: float | None = None,
    filtered: bool = False,
    detection: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> dict:
    """JSON-ready record of one camera frame.

    Args:
        world_to_camera: ``(4, 4)``: ``X_cam = T @ [X_world, 1]`` (OpenCV camera axes).
        joints_world: ``(17, 3)`` body17 joints (metres, Z up).
        uv: ``(17, 2)`` pixels (``cv2.fisheye.projectPoints`` of the joints);
        in_image, visible: ``(17,)`` bool; conf: ``(17,)``.
        bad_frame: ground truth: this frame was corrupted (interference, sync loss).
        lens_blocked: share of the image circle covered by the body at touching distance (1:
            the camera centre is inside the body); occluded: the frame shows (almost) nothing
            but that (:mod:`render_cams.fisheye.occlusion`); mean_luminance: mean grey level
            (0-255) of the image circle as recorded.
        filtered: the image filter dropped this frame (nothing detected in it).
        detection: what the 2D detector reported: ``(17, 2)`` pixels, ``(17,)`` bool
            reported, ``(17,)`` confidence (:mod:`render_cams.fisheye.detector`).
    """
    return {
        "camera": camera,
        **model.as_dict(),
        "frame": int(frame),
        "time_s": float(time_s),
        "world_to_camera": np.asarray(world_to_camera).tolist(),
        "bad_frame": bool(bad_frame),
        "occluded": bool(occluded),
        "lens_blocked": round(float(lens_blocked), 4),
        **({} if mean_luminance is None else {"mean_luminance": round(float(mean_luminance), 2)}),
        "joints": list(BODY17),
        "joints_world": np.round(joints_world, 6).tolist(),
        "keypoints_px": np.round(uv, 4).tolist(),
        "in_image": np.asarray(in_image, bool).tolist(),
        "visible": np.asarray(visible, bool).tolist(),
        "confidence": np.round(conf, 4).tolist(),
        "filtered": bool(filtered),
        **({} if detection is None else detection_fields(*detection)),
    }


def detection_fields(uv: np.ndarray, detected: np.ndarray, conf: np.ndarray) -> dict:
    """JSON-ready detector output of one frame: ``detected_px`` ``(17, 2)``, ``detected``
    ``(17,)`` bool, ``detected_confidence`` ``(17,)``."""
    return {
        "detected_px": np.round(uv, 4).tolist(),
        "detected": np.asarray(detected, bool).tolist(),
        "detected_confidence": np.round(conf, 4).tolist(),
    }


def model_from_record(record: dict) -> FisheyeModel:
    """The camera model a record describes."""
    return FisheyeModel(
        np.array(record["K"]), np.array(record["D"]), record["width"], record["height"]
    )

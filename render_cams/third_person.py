"""A third-person pinhole camera in front of the body: the control view for a 2D pose detector
(the kind of photo such detectors are trained on), beside the controller cameras' views.

The camera stands :data:`DISTANCE_M` in front of the pelvis, along the direction the hips
face (``(l_hip - r_hip) x up``, +X in the rest pose), at :data:`EYE_HEIGHT_M`, looking at
the pelvis; :data:`FOV_X_DEG` horizontal field of view, :data:`SIZE` pixels (the paper's
camera resolution, ControllerPose §4.1). Its exact body17 keypoints are the joints projected
through its ``K`` (OpenCV: ``u = fx x / z + cx``).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body17 import INDEX
from avatarsim.render_cams.fisheye.pose2d import inside
from avatarsim.render_cams.fisheye.pose_detector import ViewTruth
from avatarsim.render_cams.kinect.placement import look_at
from avatarsim.render_cams.scene import BodyScene, pinhole_K

DISTANCE_M = 3.0
EYE_HEIGHT_M = 1.0
FOV_X_DEG = 60.0
SIZE = (640, 480)  # width, height


def third_person_pose(joints: np.ndarray) -> np.ndarray:
    """``(4, 4)`` camera-to-world pose (OpenCV axes) in front of body17 joints ``(17, 3)``."""
    joints = np.asarray(joints, float)
    across = joints[INDEX["l_hip"]] - joints[INDEX["r_hip"]]
    facing = np.cross(across, [0.0, 0.0, 1.0])
    facing /= max(np.linalg.norm(facing), 1e-9)
    pelvis = joints[INDEX["pelvis"]]
    eye = pelvis + DISTANCE_M * facing
    eye[2] = EYE_HEIGHT_M
    return look_at(eye, pelvis)


def project_pinhole(K: np.ndarray, camera_to_world: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(..., 2)`` pixels of world ``points`` ``(..., 3)`` in a pinhole camera ``K``
    ``(3, 3)`` at ``camera_to_world`` ``(4, 4)`` (NaN behind the camera)."""
    rot, centre = camera_to_world[:3, :3], camera_to_world[:3, 3]
    cam = (np.asarray(points, float) - centre) @ rot
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = cam[..., :2] / cam[..., 2:] * np.diag(K)[:2] + K[:2, 2]
    return np.where(cam[..., 2:] > 0, uv, np.nan)


def render_third_person(scene: BodyScene, joints: np.ndarray) -> tuple[np.ndarray, ViewTruth]:
    """``(480, 640, 3)`` uint8 RGB of the posed ``scene`` from :func:`third_person_pose` of
    its body17 ``joints`` ``(17, 3)``, and the joints' exact keypoints in it (visibility: in
    the image; no occlusion test)."""
    width, height = SIZE
    K = pinhole_K(np.deg2rad(FOV_X_DEG), width, height)
    pose = third_person_pose(joints)
    image, _ = scene.render(pose, K, width, height)
    uv = project_pinhole(K, pose, joints)
    in_image = inside(uv, width, height)
    return image, ViewTruth(uv, in_image, in_image, in_image.astype(float))

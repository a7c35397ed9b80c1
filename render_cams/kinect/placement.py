"""Where the Kinect stands: look-at poses, the default placement, and sanity checks.

Poses are ``camera_to_world`` 4x4 matrices with OpenCV camera axes (x right, y down, z along
the optical axis), as :class:`render_cams.scene.BodyScene` takes them.
"""

from __future__ import annotations

import numpy as np

from avatar_models import Motion
from avatar_models.body import BodyDescription
from avatar_models.rigs import identify_rig
from render_cams.kinect.capsules import posed_capsules
from render_cams.kinect.sensors import KinectError

DEFAULT_DISTANCE_M = 2.0
DEFAULT_HEIGHT_M = 1.0


class KinectPlacementError(KinectError):
    """The sensor pose is unusable: not a rigid transform, or inside the user's body."""


def look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``(4, 4)`` camera-to-world pose at ``eye`` looking at ``target``, image up = world up."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    forward = target - eye
    if np.linalg.norm(forward) < 1e-9:
        raise KinectPlacementError("the sensor cannot look at its own position")
    z = forward / np.linalg.norm(forward)
    x = np.cross(z, [0.0, 0.0, 1.0])
    if np.linalg.norm(x) < 1e-9:
        raise KinectPlacementError("the sensor cannot look straight up or down")
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = eye
    return pose


def default_sensor_pose(
    motion: Motion, distance_m: float = DEFAULT_DISTANCE_M, height_m: float = DEFAULT_HEIGHT_M
) -> np.ndarray:
    """The sensor ``distance_m`` in front of the user's first-frame pelvis, ``height_m`` above
    the floor, looking horizontally back at them (the usual living-room set-up)."""
    rig = identify_rig(motion.skeleton)
    positions = motion[[0]].global_positions()[0]
    pelvis = positions[motion.skeleton.index(rig.body17["pelvis"])]
    left_hip = positions[motion.skeleton.index(rig.body17["l_hip"])]
    right_hip = positions[motion.skeleton.index(rig.body17["r_hip"])]
    left = (left_hip - right_hip) * np.array([1.0, 1.0, 0.0])
    facing = np.cross(left, [0.0, 0.0, 1.0])  # forward = left x up (rest: +Y x +Z = +X)
    facing /= np.linalg.norm(facing)
    eye = np.array([*(pelvis[:2] + distance_m * facing[:2]), height_m])
    return look_at(eye, np.array([*pelvis[:2], height_m]))


def check_sensor_pose(camera_to_world: np.ndarray, body: BodyDescription, motion: Motion) -> None:
    """Raise :class:`KinectPlacementError` unless the pose is rigid and outside the body in
    every frame."""
    pose = np.asarray(camera_to_world, float)
    if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
        raise KinectPlacementError(f"sensor pose must be a finite 4x4 matrix, got {pose.shape}")
    rot = pose[:3, :3]
    if not (np.allclose(rot.T @ rot, np.eye(3), atol=1e-6) and np.linalg.det(rot) > 0):
        raise KinectPlacementError("sensor pose rotation must be orthonormal and right-handed")
    capsules = posed_capsules(body, motion)
    eye = np.broadcast_to(pose[:3, 3], (motion.n_frames, 1, 3))
    inside = capsules.distance_to_points(eye)[:, 0] < capsules.radius
    if np.any(inside):
        frame, seg = np.argwhere(inside)[0]
        raise KinectPlacementError(
            f"sensor at {np.round(pose[:3, 3], 3).tolist()} m is inside the body "
            f"(segment {body.segments[seg].name!r} at frame {frame}); place it in front of "
            f"the user, e.g. {DEFAULT_DISTANCE_M} m away"
        )

"""Where the Kinect stands: look-at poses, the set-up for a recording, and sanity checks.

Poses are ``camera_to_world`` 4x4 matrices with OpenCV camera axes (x right, y down, z along
the optical axis), as :class:`render_cams.scene.BodyScene` takes them.

The automatic set-up (:func:`default_sensor_pose`) does what a person setting up a Kinect
for a take does: the sensor stands on a stand or TV bench at :data:`DEFAULT_HEIGHT_M`, in
front of the performer (along their mean facing direction over the take, at their mean
position sideways), looking back at them, pitched so that the optical axis passes through
the middle of the height they span (feet to head). Its distance is the nearest at which the
most joint samples of the whole take fall inside the sensor's depth range and field of view,
with :data:`RANGE_MARGIN_M` and :data:`IMAGE_MARGIN` to spare: the whole trajectory when the
range allows (Kinect V2 0.5-4.5 m; Azure Kinect NFOV unbinned 0.5-3.86 m, WFOV 2x2 binned
0.25-2.88 m: :mod:`render_cams.kinect.sensors`), as close as possible (the body then covers
the most pixels). Where a take is longer than the range (a run across a hall), the sensor
keeps the most of it in view; frames outside are NotTracked, as with a real sensor.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.body17 import INDEX
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.kinect.capsules import posed_capsules
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError, get_sensor

DEFAULT_HEIGHT_M = 0.9
"""Height of the sensor above the floor. Microsoft's placement guidance for the Kinect
(Xbox support, "Kinect sensor placement": 0.6-1.8 m, i.e. 2-6 ft, above the floor, near the
edge of a TV stand) allows a range; 0.9 m is a TV-bench or tripod height that sees feet and
head of a standing adult from 2 m with a 60 deg vertical field of view."""
RANGE_MARGIN_M = 0.15
"""Depth kept free at both ends of the sensor's range when placing it."""
IMAGE_MARGIN = 0.05
"""Share of the image width and height kept free at each border when placing the sensor."""
DISTANCE_STEP_M = 0.05
"""Resolution of the distance search."""
MAX_PLACEMENT_FRAMES = 600
"""The placement looks at most this many frames of a take (evenly spread)."""


class KinectPlacementError(KinectError):
    """The sensor pose is unusable: not a rigid transform, below the floor, or inside the
    user's body for the whole take."""


def look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``(4, 4)`` camera-to-world pose at ``eye`` looking at ``target``, image up = world up."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    if eye.shape != (3,) or target.shape != (3,) or not np.all(np.isfinite([*eye, *target])):
        raise KinectPlacementError("sensor position and target must be 3 finite numbers each")
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


def yaw_pitch_pose(position: np.ndarray, yaw_rad: float, pitch_rad: float = 0.0) -> np.ndarray:
    """``(4, 4)`` pose of a sensor at ``position`` whose optical axis points at heading
    ``yaw_rad`` (about +Z from +X: 0 looks along +X, pi/2 along +Y) and ``pitch_rad`` above
    the horizontal (negative: tilted down), image up = world up."""
    yaw, pitch = float(yaw_rad), float(pitch_rad)
    if not (np.isfinite(yaw) and np.isfinite(pitch) and abs(pitch) < 0.5 * np.pi):
        raise KinectPlacementError(
            f"sensor yaw must be finite and pitch within (-90, 90) deg, got "
            f"{np.degrees(yaw):.1f}, {np.degrees(pitch):.1f}"
        )
    position = np.asarray(position, float)
    direction = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    return look_at(position, position + direction)


def mean_facing(motion: Motion) -> np.ndarray:
    """``(2,)`` unit horizontal direction the performer faces on average over ``motion``
    (forward = left x up, left from the right hip to the left hip, averaged as unit vectors).
    A take that turns full circles has no mean: the first frame's facing is used then."""
    b17 = body17_positions(motion)
    left = b17[:, INDEX["l_hip"], :2] - b17[:, INDEX["r_hip"], :2]
    facing = np.stack([left[:, 1], -left[:, 0]], axis=1)  # (l_x, l_y, 0) x (0, 0, 1)
    facing /= np.maximum(np.linalg.norm(facing, axis=1, keepdims=True), 1e-12)
    mean = facing.mean(axis=0)
    if np.linalg.norm(mean) < 0.2:  # spins round: no prevailing direction
        mean = facing[0]
    return mean / np.linalg.norm(mean)


def in_view(
    points: np.ndarray,
    camera_to_world: np.ndarray,
    sensor: DepthSensor,
    range_margin_m: float = 0.0,
    image_margin: float = 0.0,
) -> np.ndarray:
    """``(...)`` bool: world ``points`` ``(..., 3)`` inside the sensor's depth range and
    image (shrunk by the margins) from ``camera_to_world`` ``(..., 4, 4)`` (broadcast)."""
    rot = camera_to_world[..., :3, :3]
    eye = camera_to_world[..., :3, 3]
    cam = np.einsum("...ab,...a->...b", rot, points - eye)
    z = cam[..., 2]
    near, far = sensor.range_m
    K = sensor.K
    with np.errstate(divide="ignore", invalid="ignore"):
        u = K[0, 0] * cam[..., 0] / z + K[0, 2]
        v = K[1, 1] * cam[..., 1] / z + K[1, 2]
    du, dv = image_margin * sensor.width, image_margin * sensor.height
    return (
        (z >= near + range_margin_m)
        & (z <= far - range_margin_m)
        & (u >= -0.5 + du)
        & (u <= sensor.width - 0.5 - du)
        & (v >= -0.5 + dv)
        & (v <= sensor.height - 0.5 - dv)
    )


def performer_target(motion: Motion) -> np.ndarray:
    """``(3,)`` the point a sensor set up for ``motion`` aims at: the performer's mean
    position (pelvis) at the middle of the height they span (feet to head)."""
    step = max(1, -(-motion.n_frames // MAX_PLACEMENT_FRAMES))
    b17 = body17_positions(motion[::step])
    heights = b17[..., 2]
    target_z = 0.5 * (heights.min(axis=1).mean() + heights.max(axis=1).mean())
    return np.array([*b17[:, INDEX["pelvis"], :2].mean(axis=0), target_z])


def default_sensor_pose(
    motion: Motion,
    sensor: str | DepthSensor = "kinect-v2",
    height_m: float = DEFAULT_HEIGHT_M,
) -> np.ndarray:
    """The pose a person would set the ``sensor`` up at to record ``motion`` (module
    docstring): in front of the performer's mean position along their mean facing, at
    ``height_m``, at the nearest distance that keeps the most of the take in range and view."""
    sensor = get_sensor(sensor)
    if not (np.isfinite(height_m) and 0.0 <= height_m <= 3.0):
        raise KinectPlacementError(f"sensor height must be in [0, 3] m, got {height_m}")
    step = max(1, -(-motion.n_frames // MAX_PLACEMENT_FRAMES))
    b17 = body17_positions(motion[::step])  # (T, 17, 3)
    facing = mean_facing(motion[::step])
    *centre, target_z = performer_target(motion)
    centre = np.asarray(centre)
    along = (b17[..., :2] - centre) @ facing  # (T, 17) how far ahead of the centre
    near, far = sensor.range_m
    distances = np.arange(
        near + max(along.max(), 0.0), far + max(-along.min(), 0.0), DISTANCE_STEP_M
    )
    if distances.size == 0:
        distances = np.array([near + max(along.max(), 0.0)])
    poses = np.stack(
        [look_at([*(centre + d * facing), height_m], [*centre, target_z]) for d in distances]
    )  # (D, 4, 4)
    seen = in_view(b17[None], poses[:, None, None], sensor, RANGE_MARGIN_M, IMAGE_MARGIN).mean(
        axis=(1, 2)
    )  # (D,)
    best = int(np.flatnonzero(seen >= seen.max() - 1e-9)[0])
    return poses[best]


def performer_distance(camera_to_world: np.ndarray, motion: Motion) -> np.ndarray:
    """``(T,)`` depth (metres along the optical axis) of the performer's pelvis."""
    pelvis = body17_positions(motion)[:, INDEX["pelvis"]]
    pose = np.asarray(camera_to_world, float)
    return (pelvis - pose[:3, 3]) @ pose[:3, 2]


def check_sensor_pose(camera_to_world: np.ndarray, body: BodyDescription, motion: Motion) -> None:
    """Raise :class:`KinectPlacementError` unless the pose is rigid, not below the floor, and
    outside the body in at least one frame. A performer who walks into (through) the sensor
    for some frames is recorded: those frames are closer than the sensor's near range and
    read as no depth, their joints NotTracked."""
    pose = np.asarray(camera_to_world, float)
    if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
        raise KinectPlacementError(f"sensor pose must be a finite 4x4 matrix, got {pose.shape}")
    rot = pose[:3, :3]
    if not (np.allclose(rot.T @ rot, np.eye(3), atol=1e-6) and np.linalg.det(rot) > 0):
        raise KinectPlacementError("sensor pose rotation must be orthonormal and right-handed")
    if pose[2, 3] < 0.0:
        raise KinectPlacementError(f"sensor at z = {pose[2, 3]:.3f} m is below the floor (z = 0)")
    capsules = posed_capsules(body, motion)
    eye = np.broadcast_to(pose[:3, 3], (motion.n_frames, 1, 3))
    inside = capsules.distance_to_points(eye)[:, 0] < capsules.radius
    if np.all(np.any(inside, axis=-1)):
        seg = int(np.argwhere(inside[0])[0][0])
        raise KinectPlacementError(
            f"sensor at {np.round(pose[:3, 3], 3).tolist()} m is inside the body in every "
            f"frame (segment {body.segments[seg].name!r}); place it in front of the user, "
            "or leave the pose to the automatic set-up"
        )


def orbit(pose: np.ndarray, centre: np.ndarray, yaw_rad: float) -> np.ndarray:
    """``pose (4, 4)`` turned by ``yaw_rad`` about the vertical axis through ``centre``."""
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    turn = np.eye(4)
    turn[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    turn[:3, 3] = centre - turn[:3, :3] @ centre
    return turn @ pose

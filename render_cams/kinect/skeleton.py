"""Kinect body-tracking skeletons at 30 Hz from any :class:`~avatar_models.Motion`.

The joints and their orientations on the Kinect rig come from :mod:`.rig_joints`.

Tracking state (Kinect SDK ``TrackingState``: NotTracked 0, Inferred 1, Tracked 2): NotTracked
outside the depth frustum or range, Inferred when the line of sight from the sensor to the
joint passes through a body capsule that does not contain the joint, Tracked otherwise.
Positional noise is temporally correlated Gaussian noise (AR(1)), larger at the extremities and
when Inferred.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any

import numpy as np
from scipy.signal import lfilter

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.rigs import Rig, load_rig
from avatarsim.render_cams.device import motion_at_rate, resolve_seed
from avatarsim.render_cams.kinect.capsules import posed_capsules
from avatarsim.render_cams.kinect.placement import check_sensor_pose, default_sensor_pose
from avatarsim.render_cams.kinect.rig_joints import rig_joints
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError, get_sensor
from avatarsim.render_cams.scene import body_for_motion


class TrackingState(IntEnum):
    """Kinect SDK ``TrackingState`` values (``k4abt`` confidence NONE/LOW/MEDIUM align)."""

    NOT_TRACKED = 0
    INFERRED = 1
    TRACKED = 2


EXTREMITIES = ("wrist", "hand", "thumb", "ankle", "foot")
"""Joint-name parts (lower case) of the noisier extremity joints."""


@dataclass(frozen=True)
class SkeletonNoise:
    """Joint position noise: AR(1) Gaussian with time constant ``correlation_s``.

    Standard deviations are of the order of Kinect V2 / Azure Kinect joint errors against
    marker-based capture (Wang et al., "Evaluation of pose tracking accuracy in the first and
    second generations of Microsoft Kinect", ICHI 2015; Albert et al., "Evaluation of the Pose
    Tracking Performance of the Azure Kinect and Kinect v2 for Gait Analysis", Sensors 2020),
    not a fit to them.
    """

    tracked_m: float = 0.015
    extremity_factor: float = 2.0
    inferred_factor: float = 3.0
    correlation_s: float = 0.1

    def __post_init__(self) -> None:
        values = (self.tracked_m, self.extremity_factor, self.inferred_factor, self.correlation_s)
        if not all(np.isfinite(v) and v >= 0 for v in values):
            raise KinectError(f"skeleton noise parameters must be non-negative, got {values}")


ORACLE_SKELETON = "oracle-noise"
"""``meta["skeleton"]`` of :func:`kinect_skeleton` streams: the true joints plus noise, a
fast approximation that never looks at the depth, so not a sensor's output."""
ORACLE_NOTE = (
    "not a sensor: the true joints of the simulated body plus AR(1) Gaussian noise, "
    "tracking state from geometry; no depth was tracked"
)
"""``meta["skeleton_note"]`` of those streams, carried into every output that holds one."""

NOISE_BY_RIG = {"kinect_v2": SkeletonNoise(), "azure_kinect": SkeletonNoise(tracked_m=0.01)}


@dataclass(frozen=True, eq=False)
class KinectSkeletonStream:
    """Skeleton frames. ``T`` samples, ``J`` rig joints.

    Attributes:
        rig: ``"kinect_v2"`` or ``"azure_kinect"``.
        joint_names: ``J`` names in the rig's order.
        timestamps: ``(T,)`` seconds.
        positions: ``(T, J, 3)`` world metres (Z up), noise included; meaningless where
            ``states`` is NotTracked (the JSON frames leave those out).
        orientations: ``(T, J, 4)`` world wxyz relative to the rig's T-pose.
        states: ``(T, J)`` int8 :class:`TrackingState`.
        sensor_pose: ``(4, 4)`` camera-to-world pose (OpenCV axes).
        meta: seed, device, noise settings (JSON-serialisable).
    """

    rig: str
    joint_names: tuple[str, ...]
    timestamps: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    states: np.ndarray
    sensor_pose: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return self.timestamps.shape[0]

    def camera_space(self) -> np.ndarray:
        """``(T, J, 3)`` positions in Kinect camera space: x to the sensor's left, y up,
        z out of the sensor (the SDKs' ``CameraSpacePoint`` axes), metres."""
        rot, eye = self.sensor_pose[:3, :3], self.sensor_pose[:3, 3]
        opencv = (self.positions - eye) @ rot
        return opencv * np.array([-1.0, -1.0, 1.0])

    def frame_dict(self, t: int) -> dict[str, Any]:
        """Frame ``t`` as a JSON-ready dict (positions in world and camera space).

        As the SDKs report it: a NotTracked joint has no position (``null``), and a frame in
        which no joint is tracked (the performer out of range or view) has no body
        (``body_tracked: false``)."""
        cam = self.camera_space()[t]
        states = self.states[t]

        def where(values: np.ndarray, state: int) -> list[float] | None:
            return None if state == TrackingState.NOT_TRACKED else np.round(values, 5).tolist()

        return {
            "timestamp_s": float(self.timestamps[t]),
            "rig": self.rig,
            "skeleton": self.meta.get("skeleton"),
            **{k: self.meta[k] for k in ("skeleton_note",) if k in self.meta},
            "body_tracked": bool(np.any(states != TrackingState.NOT_TRACKED)),
            "joints": [
                {
                    "name": name,
                    "position_world_m": where(self.positions[t, j], states[j]),
                    "position_camera_m": where(cam[j], states[j]),
                    "orientation_wxyz": None
                    if states[j] == TrackingState.NOT_TRACKED
                    else np.round(self.orientations[t, j], 6).tolist(),
                    "tracking_state": TrackingState(int(states[j])).name,
                }
                for j, name in enumerate(self.joint_names)
            ],
        }

    def to_json(self, t: int) -> str:
        return json.dumps(self.frame_dict(t), sort_keys=True)


def kinect_skeleton(
    motion: Motion,
    device: str | DepthSensor = "kinect-v2",
    sensor_pose: np.ndarray | None = None,
    seed: int | np.random.Generator = 0,
    noise: SkeletonNoise | None | str = "default",
    body: BodyDescription | None = None,
) -> KinectSkeletonStream:
    """The skeleton stream a Kinect at ``sensor_pose`` would report for ``motion`` at 30 Hz,
    approximated from the truth (``meta["skeleton"] = "oracle-noise"``, not a sensor: the
    depth tracker is :func:`render_cams.kinect.tracker.track`).

    Args:
        motion: any motion whose rig has a body17 map.
        device: a sensor name of :data:`~render_cams.kinect.sensors.SENSORS` or a sensor.
        sensor_pose: ``(4, 4)`` camera-to-world; default :func:`default_sensor_pose` (set up
            for this take).
        seed: randomness for the noise; recorded in ``meta``.
        noise: ``"default"`` (per-rig :data:`NOISE_BY_RIG`), a :class:`SkeletonNoise`, or
            ``None`` for exact joints.
        body: the humanoid built once for ``motion`` (``motion`` on its skeleton), for the
            occlusion tests; default: a body built from ``motion``'s skeleton.

    Joints outside the sensor's range or field of view are NotTracked in that frame: no noise
    is added to them and the JSON frames report no position for them.

    Raises:
        UnknownDeviceError, KinectPlacementError (sensor below the floor or inside the body
        for the whole take), KinectError, SceneError (motion not on ``body``'s skeleton).
    """
    sensor = get_sensor(device)
    sampled = motion_at_rate(motion, sensor.rate_hz)
    body = body_for_motion(sampled, body)
    pose = (
        default_sensor_pose(sampled, sensor)
        if sensor_pose is None
        else np.asarray(sensor_pose, float)
    )
    check_sensor_pose(pose, body, sampled)
    rig = load_rig(sensor.rig)
    positions, orientations = rig_joints(sampled, rig)
    states = tracking_states(positions, pose, sensor, posed_capsules(body, sampled))
    used_seed = resolve_seed(seed)
    model = NOISE_BY_RIG[rig.name] if isinstance(noise, str) and noise == "default" else noise
    if model is not None:
        positions = positions + _joint_noise(model, rig, states, sensor.rate_hz, used_seed)
    return KinectSkeletonStream(
        rig=rig.name,
        joint_names=rig.skeleton.names,
        timestamps=sampled.times,
        positions=positions,
        orientations=orientations,
        states=states,
        sensor_pose=pose,
        meta={
            "device": sensor.name,
            "rate_hz": sensor.rate_hz,
            "seed": used_seed,
            "noise": None if model is None else model.__dict__,
            "skeleton": ORACLE_SKELETON,
            "skeleton_note": ORACLE_NOTE,
        },
    )


def tracking_states(
    positions: np.ndarray, camera_to_world: np.ndarray, sensor: DepthSensor, capsules
) -> np.ndarray:
    """``(T, J)`` int8 :class:`TrackingState` of joints ``(T, J, 3)`` seen from the sensor."""
    rot, eye = camera_to_world[:3, :3], camera_to_world[:3, 3]
    cam = (positions - eye) @ rot
    z = cam[..., 2]
    K = sensor.K
    with np.errstate(divide="ignore", invalid="ignore"):
        u = K[0, 0] * cam[..., 0] / z + K[0, 2]
        v = K[1, 1] * cam[..., 1] / z + K[1, 2]
    near, far = sensor.range_m
    in_view = (
        (z >= near)
        & (z <= far)
        & (u >= -0.5)
        & (u <= sensor.width - 0.5)
        & (v >= -0.5)
        & (v <= sensor.height - 0.5)
    )
    # A capsule that holds the joint (or nearly) is the joint's own flesh, not an occluder.
    own = capsules.distance_to_points(positions) < capsules.radius + OWN_CAPSULE_MARGIN_M
    eyes = np.broadcast_to(eye, (positions.shape[0], 1, 3))
    crossed = capsules.distance_to_segments(eyes, positions) < capsules.radius
    occluded = np.any(crossed & ~own, axis=-1)
    states = np.where(occluded, TrackingState.INFERRED, TrackingState.TRACKED)
    return np.where(in_view, states, TrackingState.NOT_TRACKED).astype(np.int8)


OWN_CAPSULE_MARGIN_M = 0.03
"""Joints lie inside their limb; within 3 cm of a capsule's surface still counts as inside."""


def _joint_noise(
    model: SkeletonNoise, rig: Rig, states: np.ndarray, rate_hz: float, seed: int
) -> np.ndarray:
    """``(T, J, 3)`` AR(1) position noise scaled per joint and tracking state."""
    rng = np.random.default_rng(seed)
    n_frames, n_joints = states.shape
    rho = np.exp(-1.0 / (rate_hz * model.correlation_s)) if model.correlation_s > 0 else 0.0
    white = rng.standard_normal((n_frames, n_joints, 3))
    start = rng.standard_normal((1, n_joints, 3)) * rho
    unit, _ = lfilter([np.sqrt(1.0 - rho**2)], [1.0, -rho], white, axis=0, zi=start)
    extremity = np.array([any(e in n.lower() for e in EXTREMITIES) for n in rig.skeleton.names])
    sigma = model.tracked_m * np.where(extremity, model.extremity_factor, 1.0)[None]
    sigma = sigma * np.where(states == TrackingState.INFERRED, model.inferred_factor, 1.0)
    return unit * (sigma * (states != TrackingState.NOT_TRACKED))[..., None]

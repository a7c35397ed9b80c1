"""Kinect body-tracking skeletons at 30 Hz from any :class:`~avatar_models.Motion`.

Joints on a Kinect rig (``kinect_v2``: 25, ``azure_kinect``: 32) come from the motion's body17
joints: mapped joints are the body17 positions themselves; spine levels lie on the pelvis-neck
line at the rig's rest fractions; other joints (hands, hand tips, thumbs, clavicles, nose, eyes,
ears) keep their rest offset from an anchor joint, scaled by the subject's segment length and
turned with the anchor (the motion's own wrist/head rotation, or the torso frame of body17).

Orientations (world, wxyz, relative to the rig's T-pose): Kinect V2 has no bone roll, so each
joint's orientation is the shortest rotation taking its rest bone (parent -> joint) to the
current one (MoveBox paper, section IV-A1). Azure Kinect reports full orientations: the
anchor's rotation (the motion's joint rotation aligned to the rig's rest bone, or the torso
frame).

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

from avatar_models import Motion, quat
from avatar_models.body import BodyDescription
from avatar_models.body17 import INDEX
from avatar_models.rigs import Rig, identify_rig, load_rig
from render_cams.device import motion_at_rate, resolve_seed
from render_cams.kinect.capsules import posed_capsules
from render_cams.kinect.placement import check_sensor_pose, default_sensor_pose
from render_cams.kinect.sensors import DepthSensor, KinectError, get_sensor
from render_cams.scene import body_for_motion


class TrackingState(IntEnum):
    """Kinect SDK ``TrackingState`` values (``k4abt`` confidence NONE/LOW/MEDIUM align)."""

    NOT_TRACKED = 0
    INFERRED = 1
    TRACKED = 2


# body17 joint -> the body17 segment (from, to) that sets its direction and length scale.
_REFERENCE_SEGMENT = {
    "pelvis": ("pelvis", "neck"),
    "neck": ("pelvis", "neck"),
    "head": ("neck", "head"),
    **{f"{s}_shoulder": (f"{s}_shoulder", f"{s}_elbow") for s in "lr"},
    **{f"{s}_elbow": (f"{s}_elbow", f"{s}_wrist") for s in "lr"},
    **{f"{s}_wrist": (f"{s}_elbow", f"{s}_wrist") for s in "lr"},
    **{f"{s}_hip": (f"{s}_hip", f"{s}_knee") for s in "lr"},
    **{f"{s}_knee": (f"{s}_knee", f"{s}_ankle") for s in "lr"},
    **{f"{s}_ankle": (f"{s}_ankle", f"{s}_foot") for s in "lr"},
    **{f"{s}_foot": (f"{s}_ankle", f"{s}_foot") for s in "lr"},
}
# Joints anchored in the torso frame rather than by the motion's own joint rotation.
_TORSO_ANCHORS = ("pelvis", "neck")

# Anchor (body17) of every joint that is neither mapped nor on the pelvis-neck line.
EXTRA_ANCHORS: dict[str, dict[str, str]] = {
    "kinect_v2": {
        **{
            f"{j}{side}": f"{s}_wrist"
            for j in ("Hand", "HandTip", "Thumb")
            for s, side in (("l", "Left"), ("r", "Right"))
        },
    },
    "azure_kinect": {
        **{
            f"{j}_{side}": f"{s}_wrist"
            for j in ("HAND", "HANDTIP", "THUMB")
            for s, side in (("l", "LEFT"), ("r", "RIGHT"))
        },
        "CLAVICLE_LEFT": "neck",
        "CLAVICLE_RIGHT": "neck",
        **{j: "head" for j in ("NOSE", "EYE_LEFT", "EYE_RIGHT", "EAR_LEFT", "EAR_RIGHT")},
    },
}
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
    """The skeleton stream a Kinect at ``sensor_pose`` reports for ``motion`` at 30 Hz.

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
        },
    )


def rig_joints(motion: Motion, rig: Rig) -> tuple[np.ndarray, np.ndarray]:
    """``(T, J, 3)`` positions and ``(T, J, 4)`` orientations of ``rig``'s joints placed on
    ``motion`` (see the module docstring); no noise."""
    source = identify_rig(motion.skeleton)
    src_pos, src_rot = motion.fk()
    b17 = src_pos[:, source.body17_indices(motion.skeleton)]
    src_b17_rot = src_rot[:, source.body17_indices(motion.skeleton)]
    rest_src = _rest_positions(motion.skeleton)[source.body17_indices(motion.skeleton)]
    rig_rest = _rest_positions(rig.skeleton)
    rig_b17 = rig_rest[rig.body17_indices()]

    torso = _torso_frames(b17)
    torso_rest_rig = _torso_frames(rig_b17[None])[0]
    names = rig.skeleton.names
    n_frames = motion.n_frames
    positions = np.empty((n_frames, len(names), 3))
    anchor_rot = np.empty((n_frames, len(names), 3, 3))
    joint_of_b17 = {v: k for k, v in rig.body17.items()}
    spine = _spine_fractions(rig)
    extras = EXTRA_ANCHORS[rig.name]
    for j, name in enumerate(names):
        if name in joint_of_b17:
            b = joint_of_b17[name]
            positions[:, j] = b17[:, INDEX[b]]
            anchor_rot[:, j] = _anchor_rotation(b, src_b17_rot, torso, rest_src, rig_b17)
        elif name in spine:
            f = spine[name]
            positions[:, j] = (1 - f) * b17[:, INDEX["pelvis"]] + f * b17[:, INDEX["neck"]]
            anchor_rot[:, j] = torso @ torso_rest_rig.T
        else:
            b = extras[name]
            rot = _anchor_rotation(b, src_b17_rot, torso, rest_src, rig_b17)
            if b in _TORSO_ANCHORS:
                rot = torso @ torso_rest_rig.T
            a0, a1 = (INDEX[x] for x in _REFERENCE_SEGMENT[b])
            scale = np.linalg.norm(rest_src[a1] - rest_src[a0]) / np.linalg.norm(
                rig_b17[a1] - rig_b17[a0]
            )
            offset = (rig_rest[j] - rig_b17[INDEX[b]]) * scale
            positions[:, j] = b17[:, INDEX[b]] + rot @ offset
            anchor_rot[:, j] = rot
    if rig.name == "kinect_v2":
        return positions, _swing_orientations(positions, rig_rest, rig.skeleton.parents)
    return positions, quat.from_matrix(anchor_rot)


def _anchor_rotation(b17: str, src_rot, torso, rest_src, rig_b17) -> np.ndarray:
    """``(T, 3, 3)`` rotation of body17 joint ``b17`` relative to the rig's rest pose: the
    motion's joint rotation composed with the rest alignment of its reference segment (torso
    frame for pelvis and neck)."""
    if b17 in _TORSO_ANCHORS:
        return torso @ _torso_frames(rig_b17[None])[0].T
    a0, a1 = (INDEX[x] for x in _REFERENCE_SEGMENT[b17])
    align = _shortest_rotation(rig_b17[a1] - rig_b17[a0], rest_src[a1] - rest_src[a0])
    return src_rot[:, INDEX[b17]] @ align


def _rest_positions(skeleton) -> np.ndarray:
    """``(J, 3)`` world joint positions of the rest pose (identity rotations)."""
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (1, skeleton.n_joints, 1))
    return Motion(skeleton, 1.0, skeleton.offsets[:1], identity).global_positions()[0]


def _spine_fractions(rig: Rig) -> dict[str, float]:
    """Joints strictly between the rig's pelvis and neck joints -> fraction of the way up."""
    sk = rig.skeleton
    pelvis, neck = sk.index(rig.body17["pelvis"]), sk.index(rig.body17["neck"])
    chain = sk.chain(neck)
    chain = chain[chain.index(pelvis) :]
    lengths = np.cumsum(sk.bone_lengths[chain[1:]])
    return {
        sk.names[j]: float(c / lengths[-1]) for j, c in zip(chain[1:-1], lengths[:-1], strict=True)
    }


def _torso_frames(b17: np.ndarray) -> np.ndarray:
    """``(T, 3, 3)`` torso frames from body17 positions ``(T, 17, 3)``: z pelvis -> neck, y
    towards the left hip (orthogonalised), x = y x z (forward; identity in the rest pose)."""
    z = b17[:, INDEX["neck"]] - b17[:, INDEX["pelvis"]]
    z /= np.linalg.norm(z, axis=-1, keepdims=True)
    y = b17[:, INDEX["l_hip"]] - b17[:, INDEX["r_hip"]]
    y -= np.sum(y * z, -1, keepdims=True) * z
    y /= np.linalg.norm(y, axis=-1, keepdims=True)
    return np.stack([np.cross(y, z), y, z], axis=-1)


def _shortest_rotation(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` smallest rotation taking direction ``u`` to ``v`` (Rodrigues); a half
    turn about an axis perpendicular to ``u`` when they are opposite."""
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    axis = np.cross(u, v)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(u * v, -1)
    fallback = np.cross(u, np.where(np.abs(u[..., :1]) < 0.9, [1.0, 0, 0], [0, 1.0, 0]))
    axis = np.where((sin < 1e-9)[..., None], fallback, axis)
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = np.arctan2(sin, cos)
    return quat.to_matrix(quat.from_axis_angle(axis, angle))


def _swing_orientations(positions: np.ndarray, rest: np.ndarray, parents) -> np.ndarray:
    """``(T, J, 4)`` roll-free orientations: each joint's rest bone (parent -> joint; root ->
    its first child) swung onto the current bone."""
    parents = np.asarray(parents)
    first_child = int(np.flatnonzero(parents == 0)[0])
    start = np.where(parents < 0, 0, parents)
    end = np.arange(len(parents))
    end[0] = first_child
    rest_bones = rest[end] - rest[start]
    bones = positions[:, end] - positions[:, start]
    return quat.from_matrix(_shortest_rotation(np.broadcast_to(rest_bones, bones.shape), bones))


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

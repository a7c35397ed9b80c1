"""``Kinect``: a Kinect V2 or Azure Kinect depth sensor with body tracking as one ``Device``.

``Kinect(sensor).sample(motion, seed, body) -> KinectRecording`` records ``motion`` at the
sensor's 30 Hz: the skeleton stream (:mod:`.skeleton`) and the self-describing record in
memory, and the depth and body-index frames (:mod:`.depth`, one segmentation pass plus the
depth noise model of :mod:`.noise`) as :class:`DepthFrames`, rendered as they are read, so
that a long take streams to disk in constant memory (a 600 s Azure Kinect take would hold
20 GB). :func:`render_cams.kinect.sequence.write_kinect_recording` writes a recording to a
folder.

The skeleton (``skeleton=``): ``"tracker"`` (the default) runs the body-part tracker of
:mod:`.tracker` on the rendered depth frames, as the SDKs do; ``"oracle-noise"`` is the
truth-plus-noise approximation of :func:`~render_cams.kinect.skeleton.kinect_skeleton`, not a
sensor (it never looks at the depth, so it never loses or swaps a joint the way a Kinect
does), labelled so in the stream's meta, the record and every skeleton frame: a fast
stand-in where only its speed matters.

One seed drives both noises: the skeleton noise uses it as it is, the depth noise the stream
``[seed, 1]``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.render_cams.device import motion_at_rate, resolve_seed
from avatarsim.render_cams.kinect.depth import BODY_INDEX_NONE, DepthFrame, KinectDepthCamera
from avatarsim.render_cams.kinect.placement import (
    DEFAULT_HEIGHT_M,
    default_sensor_pose,
    performer_distance,
)
from avatarsim.render_cams.kinect.sensors import DepthSensor, KinectError, get_sensor
from avatarsim.render_cams.kinect.skeleton import (
    ORACLE_NOTE,
    ORACLE_SKELETON,
    KinectSkeletonStream,
    TrackingState,
    kinect_skeleton,
)
from avatarsim.render_cams.kinect.tracker import DEFAULT_MODEL, SKELETON_SOURCE, load_tracker, track
from avatarsim.render_cams.scene import BodyScene, body_for_motion


@dataclass(frozen=True, eq=False)
class DepthFrames:
    """The ``T`` depth frames of a take, rendered in order as they are iterated.

    Every pass starts the depth noise from the same seed, so every pass yields the same
    frames; :meth:`stack` holds them all at once.

    Attributes:
        motion: the take at the sensor's rate, on ``body``'s skeleton.
        body: the humanoid to render.
        camera: the posed depth camera and its noise model.
        seed: the seed of the depth noise (stream ``[seed, 1]``).
    """

    motion: Motion
    body: BodyDescription
    camera: KinectDepthCamera
    seed: int

    def __len__(self) -> int:
        return self.motion.n_frames

    def __iter__(self) -> Iterator[DepthFrame]:
        rng = np.random.default_rng([self.seed, 1])  # the skeleton noise uses seed itself
        with BodyScene(self.body) as scene:
            for t in range(self.motion.n_frames):
                scene.update(self.motion, t)
                yield self.camera.capture(scene, rng)

    def stack(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(T, H, W)`` uint16 depth in millimetres (0: no reading), ``(T, H, W)`` uint8
        body-index maps (0: body, 255: no body) and ``(T, H, W)`` uint8 body-part labels
        (:mod:`.parts`, 0: none)."""
        frames = list(self)
        return tuple(
            np.stack([getattr(f, k) for f in frames]) for k in DepthFrame.__dataclass_fields__
        )


@dataclass(frozen=True, eq=False)
class KinectRecording:
    """What a Kinect recorded: ``T`` frames of ``H x W`` pixels, ``J`` rig joints.

    Attributes:
        sensor: the depth sensor (mode, K, range).
        frames: the ``T`` depth and body-index frames (``(H, W)`` each), rendered when read.
        skeleton: the ``(T, J)`` skeleton stream.
        camera_to_world: ``(4, 4)`` sensor pose (OpenCV camera axes).
        record: the self-describing summary (device, K, D, image size, poses, seed, tracked
            share...), as JSON-ready values; it depends on the motion and seed alone.
    """

    sensor: DepthSensor
    frames: DepthFrames
    skeleton: KinectSkeletonStream
    camera_to_world: np.ndarray
    record: dict[str, Any]


SKELETONS = (SKELETON_SOURCE, ORACLE_SKELETON)
"""What the ``Kinect`` device's skeleton comes from: the depth tracker or the oracle."""


@dataclass(frozen=True, eq=False)
class Kinect:
    """A Kinect and where it stands.

    Attributes:
        sensor: a name of :data:`~render_cams.kinect.sensors.SENSORS` (e.g. ``"kinect-v2"``,
            ``"azure-kinect"``) or a sensor; after construction, the sensor.
        sensor_pose: ``(4, 4)`` camera-to-world (OpenCV axes); None: set up for each take by
            :func:`~render_cams.kinect.placement.default_sensor_pose` (in front of the
            performer, the whole take in range and view where the range allows) at
            ``sensor_height_m`` above the floor.
        max_frames: record at most this many frames (from the start).
        depth_noise, skeleton_noise: ``"default"``, a model, or ``None`` for clean output
            (``skeleton_noise`` is the oracle's).
        skeleton: :data:`SKELETONS`: ``"tracker"`` (from the depth, the default) or
            ``"oracle-noise"`` (the truth plus noise, not a sensor).
        tracker_model: the tracker's ``.npz`` model; None: the shipped one.
    """

    sensor: str | DepthSensor = "kinect-v2"
    sensor_pose: np.ndarray | None = None
    sensor_height_m: float = DEFAULT_HEIGHT_M
    max_frames: int | None = None
    depth_noise: Any = "default"
    skeleton_noise: Any = "default"
    skeleton: str = SKELETON_SOURCE
    tracker_model: str | Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "sensor", get_sensor(self.sensor))
        if self.skeleton not in SKELETONS:
            raise KinectError(f"skeleton must be one of {SKELETONS}, got {self.skeleton!r}")
        if self.max_frames is not None and self.max_frames < 1:
            raise KinectError(f"max_frames must be at least 1, got {self.max_frames}")

    @property
    def name(self) -> str:
        return self.sensor.name

    @property
    def rate_hz(self) -> float:
        return self.sensor.rate_hz

    def sample(
        self,
        motion: Motion,
        seed: int | np.random.Generator = 0,
        body: BodyDescription | None = None,
    ) -> KinectRecording:
        """The recording of ``motion`` (any rig with a body17 map).

        Args:
            body: the humanoid built once for ``motion`` (``motion`` on its skeleton);
                default: a body built from ``motion``'s skeleton.
        """
        sensor = self.sensor
        sampled = motion_at_rate(motion, sensor.rate_hz)
        if self.max_frames is not None:
            sampled = sampled[: int(self.max_frames)]
        body = body_for_motion(sampled, body)
        placed = self.sensor_pose is None
        pose = (
            default_sensor_pose(sampled, sensor, self.sensor_height_m)
            if placed
            else np.asarray(self.sensor_pose, float)
        )
        used_seed = resolve_seed(seed)
        frames = DepthFrames(
            sampled, body, KinectDepthCamera(sensor, pose, self.depth_noise), used_seed
        )
        if self.skeleton == SKELETON_SOURCE:
            model = DEFAULT_MODEL if self.tracker_model is None else self.tracker_model
            skeleton = track(frames, sensor, pose, load_tracker(model))
        else:
            skeleton = kinect_skeleton(sampled, sensor, pose, used_seed, self.skeleton_noise, body)
        states = skeleton.states
        record = {
            "device": sensor.name,
            "frames": sampled.n_frames,
            "fps": sensor.rate_hz,
            "width": sensor.width,
            "height": sensor.height,
            "K": sensor.K.tolist(),
            "D": [0.0] * 5,
            "range_m": list(sensor.range_m),
            "camera_to_world": pose.tolist(),
            "sensor_placement": "auto" if placed else "given",
            "performer_depth_m_median": round(
                float(np.median(performer_distance(pose, sampled))), 4
            ),
            "tracked_fraction": round(float(np.mean(states == TrackingState.TRACKED)), 4),
            "not_tracked_frames": int(np.sum(np.all(states == TrackingState.NOT_TRACKED, 1))),
            "world_to_camera": np.linalg.inv(pose).tolist(),
            "rig": skeleton.rig,
            "joint_names": list(skeleton.joint_names),
            "seed": used_seed,
            "skeleton": skeleton.meta["skeleton"],
            **({"skeleton_note": ORACLE_NOTE} if self.skeleton == ORACLE_SKELETON else {}),
            "depth_unit": "mm",
            "body_index_none": BODY_INDEX_NONE,
        }
        return KinectRecording(sensor, frames, skeleton, pose, record)

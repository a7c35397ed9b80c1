"""Simulated Kinect V2 and Azure Kinect: depth with a published noise model, body-index maps
and 30 Hz skeleton streams.

- :mod:`.sensors`: depth modes (size, field of view, range) with sources.
- :mod:`.noise`: axial/lateral depth noise, flying pixels, invalid pixels.
- :mod:`.depth`: depth frames and body-index maps rendered from a ``BodyScene``; PNG writers.
- :mod:`.rig_joints`: joints and orientations of the kinect_v2 / azure_kinect rigs on a motion.
- :mod:`.tracker`: the body-part tracker on the depth (the ``Kinect``'s skeleton).
- :mod:`.skeleton`: the skeleton stream; the truth-plus-noise oracle (not a sensor).
- :mod:`.device`: the ``Kinect`` device and its in-memory ``KinectRecording``.
- :mod:`.sequence`: a recording on disk (depth, body index, skeleton JSON, preview).
"""

from avatarsim.render_cams.kinect.device import SKELETONS, Kinect, KinectRecording
from avatarsim.render_cams.kinect.noise import DepthNoiseModel
from avatarsim.render_cams.kinect.placement import (
    KinectPlacementError,
    default_sensor_pose,
    look_at,
    yaw_pitch_pose,
)
from avatarsim.render_cams.kinect.sensors import SENSORS, DepthSensor, KinectError, get_sensor
from avatarsim.render_cams.kinect.sequence import read_kinect_skeleton, write_kinect_recording
from avatarsim.render_cams.kinect.skeleton import (
    KinectSkeletonStream,
    SkeletonNoise,
    TrackingState,
    kinect_skeleton,
)

__all__ = [
    "SENSORS",
    "SKELETONS",
    "DepthNoiseModel",
    "DepthSensor",
    "Kinect",
    "KinectError",
    "KinectPlacementError",
    "KinectRecording",
    "KinectSkeletonStream",
    "SkeletonNoise",
    "TrackingState",
    "default_sensor_pose",
    "get_sensor",
    "kinect_skeleton",
    "read_kinect_skeleton",
    "write_kinect_recording",
    "look_at",
    "yaw_pitch_pose",
]

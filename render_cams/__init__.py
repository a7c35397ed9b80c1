"""What devices see: VR tracking streams (and, later, Kinect skeletons/depth and cameras).

Every device follows the small :class:`~render_cams.device.Device` protocol:
``device.sample(motion, seed) -> stream``.
"""

from avatarsim.render_cams.device import Device, DeviceError
from avatarsim.render_cams.tracking import (
    StreamError,
    StreamFormatError,
    TrackingStream,
    UnknownDeviceError,
)
from avatarsim.render_cams.vr import FULL_BODY, HEADSET_AND_CONTROLLERS, VRSetup

__all__ = [
    "FULL_BODY",
    "HEADSET_AND_CONTROLLERS",
    "Device",
    "DeviceError",
    "StreamError",
    "StreamFormatError",
    "TrackingStream",
    "UnknownDeviceError",
    "VRSetup",
]

"""What devices see: VR tracking streams (and, later, Kinect skeletons/depth and cameras).

Every device follows the small :class:`~render_cams.device.Device` protocol:
``device.sample(motion, seed) -> stream``.
"""

from avatarsim.avatar_models.lazy_exports import lazy_exports
from avatarsim.render_cams.device import Device, DeviceError
from avatarsim.render_cams.tracking import (
    StreamError,
    StreamFormatError,
    TrackingStream,
    UnknownDeviceError,
)
from avatarsim.render_cams.vr import FULL_BODY, HEADSET_AND_CONTROLLERS, VRSetup

# The Kinect (depth renderer and tracker) and the controller cameras (pyrender) load on use.
_EXPORTS = {"Kinect": ".kinect", "FisheyeRig": ".fisheye.device"}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)


__all__ = [
    *_EXPORTS,
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

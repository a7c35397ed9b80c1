"""Depth sensor specifications of the Kinect V2 and the Azure Kinect depth camera.

Sources:
- Kinect for Windows v2: depth 512 x 424, 70.6 deg x 60 deg field of view, 0.5-4.5 m, 30 fps
  (Microsoft Kinect for Windows v2 product specification; Fankhauser et al. 2015, Table I).
- Azure Kinect DK hardware specification (Microsoft docs, "Azure Kinect DK hardware
  specifications", depth camera modes table): NFOV unbinned 640 x 576, 75 x 65 deg,
  0.5-3.86 m; WFOV 2x2 binned 512 x 512, 120 x 120 deg, 0.25-2.88 m; WFOV unbinned
  1024 x 1024, 120 x 120 deg, 0.25-2.21 m (15 fps in the real device; simulated at 30 Hz
  with the others so every stream shares the skeleton rate).

Every mode is modelled as an ideal pinhole with the principal point at the image centre (the
real lenses' distortion is calibrated away by the SDKs' point clouds); the focal lengths
``fx, fy`` reproduce both quoted fields of view exactly (for Kinect V2, fx = 361, fy = 367 px,
close to the fx = fy = 365 px of factory calibrations).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.kinect.noise import AZURE_KINECT_NOISE, KINECT_V2_NOISE, DepthNoiseModel
from avatarsim.render_cams.scene import pinhole_K
from avatarsim.render_cams.tracking import UnknownDeviceError

KINECT_RATE_HZ = 30.0


class KinectError(DeviceError):
    """A Kinect simulation configured with impossible values (range, pose, device)."""


@dataclass(frozen=True)
class DepthSensor:
    """One depth camera mode.

    Attributes:
        name: device name as the CLI spells it (``"kinect-v2"``, ``"azure-kinect"``...).
        width, height: depth image size in pixels.
        fov_deg: ``(horizontal, vertical)`` field of view quoted by the maker, degrees.
        range_m: ``(near, far)`` operating range; depth outside it is reported as 0.
        rig: skeleton rig of its body tracker (``"kinect_v2"`` or ``"azure_kinect"``).
        noise: the depth noise model.
        rate_hz: frame rate of depth and skeleton streams.
    """

    name: str
    width: int
    height: int
    fov_deg: tuple[float, float]
    range_m: tuple[float, float]
    rig: str
    noise: DepthNoiseModel
    rate_hz: float = KINECT_RATE_HZ

    def __post_init__(self) -> None:
        near, far = (float(x) for x in self.range_m)
        if not (np.isfinite(near) and np.isfinite(far) and 0.0 < near < far):
            raise KinectError(
                f"{self.name}: depth range must satisfy 0 < near < far, got {self.range_m!r}"
            )
        if self.width < 1 or self.height < 1:
            raise KinectError(f"{self.name}: image size must be positive")
        if not all(0.0 < float(f) < 180.0 for f in self.fov_deg):
            raise KinectError(f"{self.name}: fields of view must be in (0, 180) deg")
        object.__setattr__(self, "range_m", (near, far))

    @property
    def K(self) -> np.ndarray:
        """``(3, 3)`` pinhole intrinsics (OpenCV conventions) with both fields of view."""
        K = pinhole_K(np.radians(self.fov_deg[0]), self.width, self.height)
        K[1, 1] = 0.5 * self.height / np.tan(0.5 * np.radians(self.fov_deg[1]))
        return K


SENSORS: dict[str, DepthSensor] = {
    s.name: s
    for s in (
        DepthSensor("kinect-v2", 512, 424, (70.6, 60.0), (0.5, 4.5), "kinect_v2", KINECT_V2_NOISE),
        DepthSensor(
            "azure-kinect", 640, 576, (75.0, 65.0), (0.5, 3.86), "azure_kinect", AZURE_KINECT_NOISE
        ),
        DepthSensor(
            "azure-kinect-wfov-binned",
            512,
            512,
            (120.0, 120.0),
            (0.25, 2.88),
            "azure_kinect",
            AZURE_KINECT_NOISE,
        ),
        DepthSensor(
            "azure-kinect-wfov",
            1024,
            1024,
            (120.0, 120.0),
            (0.25, 2.21),
            "azure_kinect",
            AZURE_KINECT_NOISE,
        ),
    )
}
"""Known modes; ``"azure-kinect"`` is the NFOV unbinned mode, the SDK's default for tracking."""


def get_sensor(device: str | DepthSensor) -> DepthSensor:
    """The sensor named ``device`` (or ``device`` itself); :class:`UnknownDeviceError` if none."""
    if isinstance(device, DepthSensor):
        return device
    if device not in SENSORS:
        raise UnknownDeviceError(str(device), tuple(SENSORS))
    return SENSORS[device]

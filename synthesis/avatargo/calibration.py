"""Walk-In-Avatar calibration (AvatarGo, shared/papers/avatargo.txt §3.2): roles and scale.

The user stands in a T-pose, facing any direction, wearing six devices: a headset, two hand
controllers and three Vive trackers. SteamVR tells the device *classes* apart (headset,
controller, generic tracker) but not which tracker is on which body part, nor which
controller is in which hand. §3.2 fits a plane through the six device positions and reads
each role from where the device lies on it:

- the plane's normal (least-variance direction of the six points, ``D = 6``) is the facing
  direction, its sign chosen so that it agrees with the headset's forward axis (+X of the
  headset, :data:`render_cams.vr.placements.EYE_OFFSET_M` looks along it);
- on the plane, "up" is world +Z and "left" is ``up x facing``;
- the highest tracker is the back (root) tracker, the other two are the feet, the one
  further left the left foot; the controller further left is the left one.

Tracker orientations never enter, so any strap rotation is fine (§3.4 handles it with
``R0(T)``). The headset's height is the user's eye height; the avatar is scaled uniformly so
that its eye height matches (§3.2).

Failures raise a :class:`CalibrationError` subclass saying what the user must fix:
:class:`MissingDeviceError` (a device not tracked), :class:`NotTPoseError` (arms not
spread, hands not at shoulder height, body not upright) and :class:`SwappedTrackersError`
(trackers whose heights or sides cannot be told apart).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import CalibrationError, quat
from avatarsim.render_cams.vr import FULL_BODY
from avatarsim.synthesis.base import SynthesisError

NEEDED = {"hmd": 1, "controller": 2, "tracker": 3}
"""How many devices of each SteamVR class AvatarGo needs (§3.1)."""

ROLES = FULL_BODY
"""The roles, in the order :class:`Roles` lists them (names as in the VR setup):
hmd, left/right controller, left/right foot tracker, back tracker."""

MIN_HAND_SPAN = 0.6
"""Least controller spread along the plane, over eye height, for a T-pose (our choice: a
T-pose spreads the hands by about 0.85 of eye height, hands at the sides by ~0.35)."""
HAND_HEIGHT_BAND = (0.6, 1.1)
"""Controller height over eye height in a T-pose (our choice around the shoulder's ~0.88)."""
MAX_TILT_RAD = np.radians(30.0)
"""Largest tilt of the fitted plane from vertical for a standing user (our choice)."""
MIN_ROOT_RISE = 0.3
"""Least height of the back tracker above the higher foot tracker, over eye height (the lower
back is at ~0.55 of eye height, feet near the floor; our choice of margin)."""
MIN_FEET_GAP_M = 0.05
"""Least sideways distance between the foot trackers to tell left from right (our choice)."""


class MissingDeviceError(CalibrationError, SynthesisError):
    """A device AvatarGo needs is not tracked."""


class NotTPoseError(CalibrationError, SynthesisError):
    """The user is not standing in a T-pose."""


class SwappedTrackersError(CalibrationError, SynthesisError):
    """The trackers' positions do not tell their roles apart."""


def device_class(name: str) -> str:
    """SteamVR's class of a device named as in the VR setup: hmd, controller or tracker."""
    for suffix in ("controller", "tracker"):
        if name.endswith(suffix):
            return suffix
    if name == "hmd":
        return "hmd"
    raise SynthesisError(f"device {name!r} is neither a headset, a controller nor a tracker")


@dataclass(frozen=True)
class Roles:
    """The identified devices.

    Attributes:
        index: ``(6,)`` index, in the walk-in sample, of the device in each role of
            :data:`ROLES`.
        facing: ``(3,)`` unit horizontal direction the user faces.
        left: ``(3,)`` unit horizontal direction to the user's left.
        eye_height_m: the headset's height above the floor.
    """

    index: np.ndarray
    facing: np.ndarray
    left: np.ndarray
    eye_height_m: float

    @property
    def heading(self) -> np.ndarray:
        """wxyz turn about +Z from +X to :attr:`facing`."""
        yaw = np.arctan2(self.facing[1], self.facing[0])
        return quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(yaw))


def _by_class(classes: tuple[str, ...], ok: np.ndarray) -> dict[str, np.ndarray]:
    """Indices of the usable devices of each class; raise when one is missing."""
    out = {}
    for cls, needed in NEEDED.items():
        found = np.flatnonzero([c == cls for c in classes])
        tracked = found[ok[found]]
        if tracked.size != needed:
            lost = found.size - tracked.size
            raise MissingDeviceError(
                f"walk-in calibration needs {needed} tracked {cls}(s) and found {tracked.size}"
                + (f" ({lost} not tracked)" if lost else "")
                + f": switch on and pair the missing {cls}, keep it in view of the base "
                "stations, and calibrate again"
            )
        out[cls] = tracked
    return out


def identify_roles(
    positions: np.ndarray, quaternions: np.ndarray, classes: tuple[str, ...]
) -> Roles:
    """Each device's role from a T-pose sample (§3.2).

    Args:
        positions: ``(D, 3)`` metres, world frame (NaN for an untracked device).
        quaternions: ``(D, 4)`` wxyz; only the headset's is read (for the facing sign).
        classes: ``D`` SteamVR classes (:func:`device_class`), in any order.

    Raises:
        MissingDeviceError, NotTPoseError, SwappedTrackersError.
    """
    positions = np.asarray(positions, float)
    quaternions = np.asarray(quaternions, float)
    ok = np.isfinite(positions).all(1) & np.isfinite(quaternions).all(1)
    group = _by_class(tuple(classes), ok)
    used = np.concatenate([group["hmd"], group["controller"], group["tracker"]])
    points = positions[used]
    centred = points - points.mean(0)
    normal = np.linalg.svd(centred)[2][-1]
    if abs(normal[2]) > np.sin(MAX_TILT_RAD):
        raise NotTPoseError(
            "the devices do not lie in a vertical plane: stand upright in a T-pose "
            "(arms spread sideways at shoulder height, feet on the floor) and calibrate again"
        )
    facing = np.array([normal[0], normal[1], 0.0])
    facing /= np.linalg.norm(facing)
    hmd = int(group["hmd"][0])
    if facing @ quat.rotate(quaternions[hmd], np.array([1.0, 0.0, 0.0])) < 0:
        facing = -facing
    left = np.cross([0.0, 0.0, 1.0], facing)
    eye = float(positions[hmd, 2])
    side = positions @ left  # (D,) metres along the user's left

    hands = group["controller"][np.argsort(-side[group["controller"]])]  # left first
    span = side[hands[0]] - side[hands[1]]
    heights = positions[hands, 2] / eye
    if span < MIN_HAND_SPAN * eye or not (
        (heights > HAND_HEIGHT_BAND[0]).all() and (heights < HAND_HEIGHT_BAND[1]).all()
    ):
        raise NotTPoseError(
            f"the controllers are {span:.2f} m apart at {heights.min():.2f}-{heights.max():.2f}"
            " of eye height; a T-pose spreads them sideways at shoulder height: spread your "
            "arms and calibrate again"
        )

    trackers = group["tracker"][np.argsort(-positions[group["tracker"], 2])]  # highest first
    back, feet = trackers[0], trackers[1:]
    rise = positions[back, 2] - positions[feet, 2].max()
    if rise < MIN_ROOT_RISE * eye:
        raise SwappedTrackersError(
            f"no tracker is clearly above the others (the highest is {rise:.2f} m above the "
            "next): strap one tracker on the lower back and one on each foot, and calibrate "
            "again"
        )
    feet = feet[np.argsort(-side[feet])]  # left first
    if side[feet[0]] - side[feet[1]] < MIN_FEET_GAP_M:
        raise SwappedTrackersError(
            "the two low trackers are not side by side: strap one on each foot, stand with "
            "the feet apart, and calibrate again"
        )
    index = np.array([hmd, hands[0], hands[1], feet[0], feet[1], back])
    return Roles(index, facing, left, eye)


def classes_of(names: tuple[str, ...]) -> tuple[str, ...]:
    """SteamVR classes of devices named as in the VR setup."""
    return tuple(device_class(n) for n in names)

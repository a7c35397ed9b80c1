"""Where each VR device sits on the body: nominal attachments for the six-device setup.

The setup is AvatarGo's (shared/papers/avatargo.txt §3.1): a headset, two hand controllers and
three Vive trackers, on both feet and on the lower back. CoolMoves (coolmoves.txt §3) uses the
first three only. Offsets are written in the body frame at rest (+X forward, +Y left, +Z up;
see :mod:`render_cams.vr.attachments`). They are plausible adult values chosen here, not
measurements; per-user variation is added by :class:`~render_cams.vr.attachments.OffsetSpread`
or by explicit per-device ``offsets`` (:class:`~render_cams.vr.setup.VRSetup`). Nothing here
calibrates: AvatarGo's walk-in calibration (:mod:`synthesis.avatargo`) does not estimate these
offsets back, it stores each tracker's offset to the avatar's joint at a T-pose (§3.3).

- ``hmd``: on the head joint, 9 cm forward and 8 cm up (between the eyes, where the headset's
  tracking origin is), looking along +X with +Z up.
- ``left_controller`` / ``right_controller``: in the palm, 8 cm from the wrist joint along the
  forearm, with the controller's +X (its pointing axis) along the rig's rest forearm
  (elbow -> wrist) and +Z (towards its tracking ring, ControllerPose §4.1's "upper ring") on
  the thumb side of the hand: a power grip closes round the grip's handle across the palm, the
  ring above the thumb and the grip's bottom below the little finger. The thumb side is taken
  as the body's forward axis at rest, which it is for a T-pose with the palms down and for
  arms hanging with the palms in; a rest forearm along that axis falls back to world up.
- ``left_foot_tracker`` / ``right_foot_tracker``: on the instep, 6 cm in front of the ankle
  joint and 2 cm above it, level and facing forward.
- ``back_tracker``: on the lower back, 10 cm behind and 5 cm above the pelvis joint, facing
  backwards (turned 180 degrees about +Z), as a puck strapped to a belt.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Skeleton, quat
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.tracking import UnknownDeviceError
from avatarsim.render_cams.vr.attachments import Attachment

HEADSET_AND_CONTROLLERS: tuple[str, ...] = ("hmd", "left_controller", "right_controller")
FULL_BODY: tuple[str, ...] = (
    *HEADSET_AND_CONTROLLERS,
    "left_foot_tracker",
    "right_foot_tracker",
    "back_tracker",
)

EYE_OFFSET_M = np.array([0.09, 0.0, 0.08])
GRIP_DISTANCE_M = 0.08
INSTEP_OFFSET_M = np.array([0.06, 0.0, 0.02])
LOWER_BACK_OFFSET_M = np.array([-0.10, 0.0, 0.05])
_FACING_BACK = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array(np.pi))

_FIXED: dict[str, Attachment] = {
    "hmd": Attachment("head", EYE_OFFSET_M),
    "left_foot_tracker": Attachment("l_ankle", INSTEP_OFFSET_M),
    "right_foot_tracker": Attachment("r_ankle", INSTEP_OFFSET_M),
    "back_tracker": Attachment("pelvis", LOWER_BACK_OFFSET_M, _FACING_BACK),
}
_HANDS = {"left_controller": "l", "right_controller": "r"}


def _grip(skeleton: Skeleton, side: str) -> Attachment:
    """Controller in the ``side`` hand: +X along the rig's rest forearm, +Z the thumb side."""
    rig = identify_rig(skeleton)
    rest = skeleton.rest_positions()
    elbow, wrist = (rest[skeleton.index(rig.body17[f"{side}_{j}"])] for j in ("elbow", "wrist"))
    forward = (wrist - elbow) / np.linalg.norm(wrist - elbow)
    # Controller +Z: the thumb side, the body's forward axis at rest with its forearm
    # component removed; a rest forearm pointing forward has none, so fall back to world up.
    up = np.array([1.0, 0.0, 0.0])
    if abs(forward @ up) > 0.9:
        up = np.array([0.0, 0.0, 1.0])
    up = up - (up @ forward) * forward
    up /= np.linalg.norm(up)
    frame = np.stack([forward, np.cross(up, forward), up], axis=1)  # columns: x, y, z
    return Attachment(f"{side}_wrist", GRIP_DISTANCE_M * forward, quat.from_matrix(frame))


def nominal_attachment(device: str, skeleton: Skeleton) -> Attachment:
    """The nominal :class:`Attachment` of ``device`` (a name in :data:`FULL_BODY`)."""
    if device in _HANDS:
        return _grip(skeleton, _HANDS[device])
    if device in _FIXED:
        return _FIXED[device]
    raise UnknownDeviceError(device, FULL_BODY)

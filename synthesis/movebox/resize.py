"""Avatar resizing to the user (MoveBox §III-B4): "the resizing feature takes the three
dimensional positions of the user's foot and head bones, which are captured by the Azure
Kinect or Kinect v2 camera, to measure the user's height. The Rocketbox avatar is then
resized, by its scale component, to match the user's height."

The Kinect head and foot joints are not the head top and the sole: the measured head-to-foot
height is scaled by the avatar's own stature over its rest head-to-foot joint height (the
body17 head and foot joints, where the Kinect rigs put theirs). Resizing is triggered while
the user stands (the paper's button): the median over the frames given, which the joint
noise does not bias (a high percentile read 3 cm tall at 1.58 m and 1.90 m).
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import Skeleton
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import identify_rig, load_rig
from avatarsim.render_cams.kinect import KinectSkeletonStream, TrackingState
from avatarsim.synthesis.base import SynthesisError

AVATAR_JOINTS = ("Bip01 Pelvis", "Bip01 Spine", "Bip01 L UpperArm", "Bip01 R Thigh")
"""Joints that tell an avatar-rig skeleton (the 3ds Max Biped names)."""


def head_to_foot_m(kinect: KinectSkeletonStream) -> np.ndarray:
    """``(N,)`` head-joint height over the lower foot joint, in frames where the head and both
    feet are Tracked (NaN elsewhere)."""
    rig = load_rig(kinect.rig)
    names = kinect.joint_names
    head = names.index(rig.body17["head"])
    feet = [names.index(rig.body17[f]) for f in ("l_foot", "r_foot")]
    tracked = (kinect.states[:, [head, *feet]] == TrackingState.TRACKED).all(axis=1)
    z = kinect.positions[..., 2]
    height = z[:, head] - z[:, feet].min(axis=1)
    return np.where(tracked, height, np.nan)


def user_height_m(kinect: KinectSkeletonStream, avatar: Skeleton) -> float:
    """The user's standing height measured from the stream (the user standing in it), in
    ``avatar``'s stature terms.

    Raises:
        SynthesisError: no frame has the head and both feet Tracked.
    """
    heights = head_to_foot_m(kinect)
    if not np.isfinite(heights).any():
        raise SynthesisError(
            f"cannot measure the user's height: no {kinect.rig} frame tracks the head and "
            "both feet (stand in full view of the sensor)"
        )
    rig = identify_rig(avatar)
    rest_z = avatar.rest_positions()[:, 2]
    head, foot = (avatar.index(rig.body17[b]) for b in ("head", "l_foot"))
    ratio = standing_height(avatar) / (rest_z[head] - rest_z[foot])
    return float(np.nanmedian(heights) * ratio)


def resized(avatar: Skeleton, height_m: float) -> Skeleton:
    """``avatar`` scaled uniformly (its scale component) to stand ``height_m`` tall."""
    if not (np.isfinite(height_m) and height_m > 0):
        raise SynthesisError(f"an avatar height must be positive, got {height_m!r}")
    return avatar.scaled(height_m / standing_height(avatar))


def avatar_for(rig: Skeleton, height_m: float) -> Skeleton:
    """The skeleton MoveBox drives for a user scored on ``rig``: ``rig`` itself when it is an
    avatar-rig skeleton (any proportions), else the avatar resized to ``height_m``."""
    if all(name in rig for name in AVATAR_JOINTS):
        return rig
    return resized(load_rig("avatar").skeleton, height_m)

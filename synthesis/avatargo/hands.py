"""Hands on the controllers (AvatarGo §3.4 "Hands"): the palm over the controller's centre.

The wrist is placed so that the controller always sits under the palm, at an exact
palm-to-wrist offset: with ``c`` the palm point in the wrist frame where the controller's
tracked centre is held (:class:`Grip`; the simulated devices' convention,
:func:`render_cams.vr.nominal_attachment`: in the palm, along the rest forearm),
``R_t(wrist) = R_t(C) R0(C)^-1 R0(wrist)`` (eq. 3 with the controller as tracker) and
``p_t(wrist) = p_t(C) - R_t(wrist) c``, i.e. a :class:`~synthesis.avatargo.offsets.
TrackerOffsets` (:func:`palm_offsets`). Where the avatar's arm is too short to put the wrist
there (:func:`out_of_reach`: the wrist's goal further from the shoulder than the arm's
length), the IK leaves the hand as close as it gets and the virtual controller is attached
to the hand instead of the physical one (§3.4); :func:`palm_distance` measures how far the
palm's controller point ended from the tracked controller.

The controller's body is a capsule (its handle): :data:`CONTROLLER_RADIUS_M`,
:data:`HANDLE_LENGTH_M`, lying across the palm (along the knuckle line) right under the palm
point; the finger IK (:mod:`synthesis.avatargo.fingers`) closes the fingers on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Skeleton, quat
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.vr import nominal_attachment
from avatarsim.synthesis.avatargo.offsets import TrackerOffsets

CONTROLLER_RADIUS_M = 0.02
HANDLE_LENGTH_M = 0.10
"""A Vive wand's handle: about 4 cm thick and 10 cm long where the hand holds it (our
measurement of the published drawings, rounded)."""
PALM_HALF_THICKNESS_M = 0.012
"""From the hand's bone line to the palm's skin (our choice: half of a ~2.5 cm thick hand);
deeper where a rest finger bone (the thumb's) lies further below, plus
:data:`FINGER_CLEARANCE_M`: the open hand must not start inside the handle."""
FINGER_CLEARANCE_M = 0.001
REACH_SLACK_M = 0.005
"""A wrist goal counts as out of reach beyond the arm's length plus this (our choice: the
IK's joint limits keep the elbow a few degrees from straight)."""
PALM_NORMAL = np.array([0.0, 0.0, -1.0])
"""Out of the palm, in the hand frame: the rigs' rest T-pose has the palms down."""
KNUCKLES = ("Finger1", "Finger4")
"""The avatar rig's index and little finger roots: they span the knuckle line."""


def finger_joint(side: str, finger: int, segment: str = "") -> str:
    """The avatar rig's name of a finger bone: ``side`` "L"/"R", ``finger`` 0 (thumb) to 4,
    ``segment`` "" (the root), "1", "2" or "Nub" (the tip)."""
    return f"Bip01 {side} Finger{finger}{segment}"


def has_fingers(skeleton: Skeleton) -> bool:
    """Whether ``skeleton`` has the avatar rig's finger bones."""
    return all(
        finger_joint(s, f, seg) in skeleton
        for s in "LR"
        for f in range(5)
        for seg in ("", "1", "2", "Nub")
    )


@dataclass(frozen=True)
class Grip:
    """Where each hand holds its controller, in the wrist frames (left, right).

    Attributes:
        palm: ``(2, 3)`` the palm point that holds the controller's tracked centre.
        handle: ``(2, 2, 3)`` the capsule's end points ``s, e`` (eq. 5), under the palm.
    """

    palm: np.ndarray
    handle: np.ndarray


def grip_of(skeleton: Skeleton) -> Grip:
    """The controllers under the palms of ``skeleton`` (its rest pose, hand frames).

    The palm point is the controllers' nominal grip on the rig
    (:func:`~render_cams.vr.nominal_attachment`). With the avatar rig's finger bones the
    handle lies along the knuckle line, its top below every rest finger bone; on a rig
    without fingers it lies forward (+X).
    """
    rig = identify_rig(skeleton)
    rest = skeleton.rest_positions()
    palms, handles = [], []
    for side, device in (("L", "left_controller"), ("R", "right_controller")):
        palm = nominal_attachment(device, skeleton).position
        wrist = rest[skeleton.index(rig.body17[f"{side.lower()}_wrist"])]
        if has_fingers(skeleton):
            ends = rest[skeleton.indices([finger_joint(side, int(k[-1])) for k in KNUCKLES])]
            across = ends[0] - ends[1]
            bones = [finger_joint(side, f, g) for f in range(5) for g in ("", "1", "2", "Nub")]
            depth = ((rest[skeleton.indices(bones)] - wrist) @ PALM_NORMAL).max()
            skin = max(PALM_HALF_THICKNESS_M, depth + FINGER_CLEARANCE_M)
        else:
            across = np.array([1.0, 0.0, 0.0])
            skin = PALM_HALF_THICKNESS_M
        across = across - (across @ PALM_NORMAL) * PALM_NORMAL
        across /= np.linalg.norm(across)
        centre = palm + (CONTROLLER_RADIUS_M + skin) * PALM_NORMAL
        palms.append(palm)
        handles.append(centre + 0.5 * HANDLE_LENGTH_M * np.stack([-across, across]))
    return Grip(np.stack(palms), np.stack(handles))


def palm_offsets(controller_rot0: np.ndarray, wrist_rot0: np.ndarray, grip: Grip) -> TrackerOffsets:
    """The wrists in their controllers' frames: eq. 3 for the rotation (``R0(C)^-1
    R0(wrist)``) and the exact palm-to-wrist offset for the position, from the walk-in
    controller rotations ``(2, 4)`` and the avatar's wrist rotations ``(2, 4)``."""
    rotation = quat.mul(quat.conj(quat.normalize(controller_rot0)), wrist_rot0)
    return TrackerOffsets(-quat.rotate(rotation, grip.palm), rotation)


def palm_distance(
    wrist_pos: np.ndarray, wrist_rot: np.ndarray, controller_pos: np.ndarray, grip: Grip
) -> np.ndarray:
    """``(B, 2)`` metres from the palm's controller point of the solved wrists
    (``wrist_pos (B, 2, 3)``, rotation matrices ``wrist_rot (B, 2, 3, 3)``) to the tracked
    controllers ``(B, 2, 3)``."""
    gap = wrist_pos + (wrist_rot @ grip.palm[..., None])[..., 0] - controller_pos
    return np.sqrt(np.add.reduce(gap * gap, axis=-1))  # np.linalg.norm's sum (a tick's path)


def out_of_reach(shoulders: np.ndarray, wrist_goals: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """``(B, 2)`` whether each wrist goal ``(B, 2, 3)`` lies beyond the arm's length
    ``arm (2,)`` (plus :data:`REACH_SLACK_M`) from its shoulder ``(B, 2, 3)``: there the
    virtual controller is attached to the hand (§3.4)."""
    reach = wrist_goals - shoulders
    return beyond_reach(np.sqrt(np.add.reduce(reach * reach, axis=-1)), arm)


def beyond_reach(distance: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """:func:`out_of_reach` of wrist goals ``distance (B, 2)`` metres from their shoulders
    (for a solver that has the distances already)."""
    return distance > arm + REACH_SLACK_M

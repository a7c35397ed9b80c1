"""Foot-contact clean-up of synthesised poses (beyond the paper, which admits foot sliding, §6).

Contact labels follow the physics-based character literature (UHC, Luo et al. 2021; PhysDiff,
Yuan et al. 2023, and ``sim.thresholds``), by :func:`avatar_models.foot_contact.contact_mask`
(the ankles' backward-difference vertical speed, causal for ``step()``): a foot is in
contact when its ankle is less than ``CONTACT_HEIGHT_M`` above the height it has standing on
the floor AND its vertical speed is below ``CONTACT_VZ_M_S`` (the vertical speed only, so
that a sliding foot still counts as in contact: that is the skating to remove).

Clean-up, causal so that it runs in ``step()``: at the first frame of a stance the ankle's
horizontal position becomes the anchor; while the stance lasts, the ankle's target is the
anchor at floor height, faded in over ``BLEND_IN_S``; after lift-off the target fades back to
the free (synthesised) ankle over ``BLEND_OUT_S``. The leg reaches the target by two-bone IK
(:mod:`synthesis.two_bone`, hip-knee-ankle, knee pole from the synthesised pose, foot
orientation kept).

The state machine is recursive (each frame needs the previous one's anchor and fade), so
batch and streaming both run :meth:`FootContact.update` frame after frame, on ``(2, 3)``
arrays.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.foot_contact import contact_mask

CONTACT_HEIGHT_M = 0.05
"""Foot-contact height of UHC and PhysDiff (5 cm), above the ankle's standing height."""
CONTACT_VZ_M_S = 0.3
"""Vertical ankle speed below which a low foot is planted (our choice; a heel strike at
walking pace descends at about 0.3-0.5 m/s just before contact)."""
BLEND_IN_S = 0.03
"""Fade-in of the pin: short, since a stance's first frame is already at the anchor."""
BLEND_OUT_S = 0.1
"""Fade-out after lift-off, so that the foot does not jump back to the free pose."""
RELEASE_HEIGHT_M = 0.1
"""Hysteresis: a pinned foot stays pinned until its free (synthesised) ankle rises this far
above standing height; synthesised feet pass the floor without stopping, so the contact
test alone would pin for a frame or two at a time."""
STEP_HEIGHT_M = 0.09
"""Apex of the arc a released foot takes back to the free pose (our choice, on the generated
cross-subject run and dribble: the arc clears the 5 cm contact height for most of its frames
without lifting the foot far from the truth)."""
MAX_REACH = 0.999
"""A stance ends once its anchor is farther from the hip than this share of the leg's length:
a body carried on by the headset would otherwise drag a straight leg behind it."""
MAX_SLIP_M = 0.1
"""A stance ends once the free (synthesised) ankle is this far from the anchor horizontally:
the database pose has taken a step the pin would otherwise cancel."""


def contacts(ankles: np.ndarray, standing_z: np.ndarray, rate_hz: float) -> np.ndarray:
    """``(T, 2)`` contact labels of ankle positions ``(T, 2, 3)`` (world) given the ankles'
    standing heights ``(T|1, 2|1)``; the first frame's vertical speed counts as 0."""
    vz = np.diff(ankles[..., 2], axis=0, prepend=ankles[:1, :, 2]) * rate_hz
    return contact_mask(
        ankles[..., 2],
        CONTACT_HEIGHT_M,
        floor=standing_z,
        vertical_velocity=vz,
        max_vertical_speed=CONTACT_VZ_M_S,
    )


class FootContact:
    """Causal stance detection and ankle targets for both feet.

    Args:
        rate_hz: frame rate of the poses.
    """

    def __init__(self, rate_hz: float):
        self.rate_hz = float(rate_hz)
        self.step_in = 1.0 / max(BLEND_IN_S * rate_hz, 1.0)
        self.step_out = 1.0 / max(BLEND_OUT_S * rate_hz, 1.0)
        self.reset()

    def reset(self) -> None:
        self.previous: np.ndarray | None = None  # (2, 3) last free ankles
        self.in_stance = np.zeros(2, bool)
        self.anchor = np.zeros((2, 3))
        self.fade = np.zeros(2)

    def update(
        self, ankles: np.ndarray, hips: np.ndarray, leg_m: float, standing_z: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Targets ``(2, 3)`` for the free ankles ``(2, 3)`` of one frame (hips ``(2, 3)``,
        leg length ``leg_m``), and the fade ``(2,)`` (0: the target is the free ankle)."""
        previous = ankles if self.previous is None else self.previous
        contact = contacts(np.stack([previous, ankles]), standing_z, self.rate_hz)[1]
        self.previous = ankles
        # A new stance anchors where the free foot is; an old one ends when out of reach.
        onset = contact & ~self.in_stance
        self.anchor[onset, :2] = ankles[onset, :2]
        self.anchor[:, 2] = standing_z
        reachable = np.linalg.norm(self.anchor - hips, axis=-1) <= MAX_REACH * leg_m
        low = ankles[:, 2] - standing_z < RELEASE_HEIGHT_M
        near = np.linalg.norm(ankles[:, :2] - self.anchor[:, :2], axis=-1) < MAX_SLIP_M
        self.in_stance = onset | (self.in_stance & low & near & reachable)
        contact = self.in_stance
        self.fade = np.clip(
            np.where(contact, self.fade + self.step_in, self.fade - self.step_out), 0.0, 1.0
        )
        # In stance the foot is at the anchor at once horizontally (the anchor is where the
        # free foot touched down) and fades to floor height; after lift-off it returns to the
        # free foot along an arc of STEP_HEIGHT_M, a step rather than a slide on the floor.
        pull = np.where(contact, 1.0, self.fade)
        target = ankles + pull[:, None] * (self.anchor - ankles)
        target[:, 2] = ankles[:, 2] + self.fade * (standing_z - ankles[:, 2])
        target[:, 2] += np.where(contact, 0.0, 4.0 * STEP_HEIGHT_M * self.fade * (1 - self.fade))
        return target, np.maximum(pull, self.fade)


def skating_cm_s(ankles: np.ndarray, contact: np.ndarray, rate_hz: float) -> float:
    """Mean horizontal ankle speed (cm/s) over contact frames: ``ankles (T, 2, 3)``,
    ``contact (T, 2)``. Speeds are backward differences (frame 0 excluded)."""
    speed = np.linalg.norm(np.diff(ankles[..., :2], axis=0), axis=-1) * rate_hz
    stance = contact[1:]
    return float(100.0 * speed[stance].mean()) if stance.any() else 0.0

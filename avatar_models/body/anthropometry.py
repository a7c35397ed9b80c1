"""Anthropometric tables: segment masses, centres of mass, radii and a few proportions.

Mass fractions and centre-of-mass positions are de Leva (1996), *Adjustments to
Zatsiorsky-Seluyanov's segment inertia parameters*, J. Biomech. 29(9):1223-1230, Table 4
(male). The trunk is split as de Leva splits it: lower trunk (LPT, 11.17 %) is our ``pelvis``,
middle + upper trunk (MPT 16.33 % + UPT 15.96 %) is our ``torso``; ``head`` includes the neck.
The fractions sum to 100 % (head + trunk + 2 x (upper arm, forearm, hand, thigh, shank, foot)).

``com`` is the centre of mass as a fraction of a bone's length from its proximal joint (the
one nearer the pelvis). de Leva measures the trunk from CERV down; our trunk bones run
upwards, so they use 1 - 0.4486. The head is a sphere and its mass sits at its centre.

Radii are ``circumference / (2 pi)`` of ANSUR II male means (Gordon et al. 2014, *2012
Anthropometric Survey of U.S. Army Personnel*, stature 1756 mm), divided by that stature so
they scale with the body. A capsule has one radius for a tapering limb, so it takes the mean
of the proximal and distal girths: thigh (616 mm) and lower thigh (407 mm), calf (391 mm) and
ankle (225 mm), forearm (flexed, 299 mm) and wrist (175 mm); the upper arm uses the biceps
(flexed, 358 mm), the hand the wrist, the neck its own girth (398 mm), the skull the head
circumference (573 mm). A circle of the chest circumference would be a third deeper than a
real chest, so the trunk capsules use half the chest depth (255 mm) and the pelvis half the
buttock depth (250 mm). Feet are boxes of ANSUR II foot length (270 mm) and foot breadth
(101 mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

ANSUR_STATURE_M = 1.756


def _radius_from_circumference(*circumferences_m: float) -> float:
    """Radius / stature of a circle with the mean of the given ANSUR II circumferences."""
    return sum(circumferences_m) / len(circumferences_m) / math.tau / ANSUR_STATURE_M


@dataclass(frozen=True)
class SegmentParameters:
    """de Leva mass fraction (of body mass), CoM fraction along the bone, radius / stature."""

    mass_fraction: float
    com: float
    radius_ratio: float


SEGMENTS: dict[str, SegmentParameters] = {
    "pelvis": SegmentParameters(0.1117, 0.6115, 0.125 / ANSUR_STATURE_M),
    "torso": SegmentParameters(0.1633 + 0.1596, 1.0 - 0.4486, 0.1275 / ANSUR_STATURE_M),
    "head": SegmentParameters(0.0694, 0.5, _radius_from_circumference(0.398)),
    "upper_arm": SegmentParameters(0.0271, 0.5772, _radius_from_circumference(0.358)),
    "forearm": SegmentParameters(0.0162, 0.4574, _radius_from_circumference(0.299, 0.175)),
    "hand": SegmentParameters(0.0061, 0.7900, _radius_from_circumference(0.175)),
    "thigh": SegmentParameters(0.1416, 0.4095, _radius_from_circumference(0.616, 0.407)),
    "shank": SegmentParameters(0.0433, 0.4459, _radius_from_circumference(0.391, 0.225)),
    "foot": SegmentParameters(0.0137, 0.4415, 0.101 / 2 / ANSUR_STATURE_M),
}
"""Per segment kind. ``head`` radius is the neck's (the skull is :data:`HEAD_RADIUS_RATIO`);
``foot`` radius is half the foot breadth (the box's half width, or the capsule's radius)."""

SINGLE_SEGMENTS = ("pelvis", "torso", "head")
"""Kinds that exist once; every other kind exists on the left and on the right."""

HEAD_RADIUS_RATIO = _radius_from_circumference(0.573)
"""Skull sphere radius / stature, from ANSUR II head circumference (573 mm)."""

FOOT_LENGTH_RATIO = 0.270 / ANSUR_STATURE_M
"""Heel to toe tip / stature (ANSUR II foot length)."""

HEEL_FRACTION = 0.25
"""Part of the foot length behind the ankle joint (the lateral malleolus lies about a quarter
of the foot length in front of the heel)."""

HAND_LENGTH_RATIO = 0.0862 / 0.2689
"""Wrist to third metacarpal head / forearm length, de Leva (1996) Table 4 (86.2 / 268.9 mm),
for rigs whose hand has no child joints to measure it by."""

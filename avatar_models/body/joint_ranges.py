"""Anatomical joint ranges per joint role, and the Euler order of each role's three hinges.

Axes are the joint's local axes, which in the rest pose are the world axes (the character
faces +X, left is +Y, Z is up; rest local rotations are the identity). For a LEFT limb:

- about Y (the sagittal axis of rotation): +Y bends a downward bone backwards, an upward
  bone forwards, a forward bone downwards: hip flexion is -ry, knee flexion +ry, ankle
  plantarflexion +ry, toe flexion +ry (toe extension, the toes bent up at push-off, -ry),
  spine and neck flexion +ry;
- about X: +rx moves a downward leg outwards (abduction), a sideways (+Y) arm upwards, and
  everts the foot;
- about Z: +rz turns a forward-pointing foot outwards and swings a sideways arm backwards.

Right-side ranges are the mirror image: the rotation about Y is kept, rotations about X and Z
change sign (as in :meth:`avatar_models.motion.Motion.mirror`).

Degrees are the AAOS average ranges of motion (Greene & Heckman 1994, *The Clinical
Measurement of Joint Motion*, AAOS; the same values as AAOS 1965, *Joint Motion: Method of
Measuring and Recording*): hip flexion 120 / extension 30 / abduction 45 / adduction 30 /
internal and external rotation 45; knee flexion 135 (+10 hyperextension); ankle
plantarflexion 50, inversion 35 / eversion 15; first metatarsophalangeal (toe) flexion 45 /
extension 70; shoulder abduction 180 /
adduction 30, horizontal flexion 135 / extension 45, internal rotation 70 / external 90;
elbow flexion 150, pronation and supination 80; wrist flexion 80 / extension 70, radial
deviation 20 / ulnar 30; thoracolumbar spine flexion 80 / extension 25 / lateral bending 35 /
rotation 45; cervical spine flexion 45 / extension 45 / lateral bending 45 / rotation 60.
Ankle dorsiflexion is the weight-bearing value, 40 degrees (lunge test, Bennell et al. 1998,
Aust. J. Physiother. 44(3):175-180), not AAOS's non-weight-bearing 20: the body squats and
walks under load. Sternoclavicular ranges are Kapandji (*The Physiology of the Joints*,
vol. 1): elevation 45, depression 10, protraction 15, retraction 30, axial rotation 30.
Shoulder abduction is measured from the arm at the side, the rest pose has the arm
horizontal (T-pose), so rx = abduction - 90. Elbow flexion is about Z because the rest pose
has the palms down.

Degrees of freedom a joint does not have anatomically (knee and elbow varus/valgus, wrist
axial rotation, the pelvic girdle, toe abduction and axial rotation) get a small allowance so
the hinge still exists for exact kinematic replay; joints between the skeleton root and the
pelvis are part of the free root and get the full circle.

The spine and the neck are chains of several joints in most rigs (CMU: LowerBack, Spine,
Spine1 and Neck, Neck1, Head). A shared role's range is the whole chain's: it limits the
chain's total rotation, that of its last segment relative to the segment above the chain
(:attr:`~avatar_models.body.description.BodyDescription.chains`). It is not divided over the
chain's joints: real rigs distribute a bend unevenly and even oppositely (CMU 14_33's neck: the
lower neck at -19 degrees, the upper neck at +37, the head at +16, 34 in all), so each joint
gets the whole range, the most any part of the chain can bend, and the chain's total is
limited on its own (the chain check of :mod:`sim.checks.joint_limits`; in the MJCF a fixed
tendon limits the sum of the chain's angles per axis, the total to first order).
"""

from __future__ import annotations

import numpy as np

# role -> (Euler order of the hinges, {axis: (lo, hi) degrees, left side}, shared by a chain:
# consecutive joints of the role form one anatomical joint whose range limits their sum)
ROLE_TABLE: dict[str, tuple[str, dict[str, tuple[float, float]], bool]] = {
    "root_chain": ("YXZ", {"x": (-180, 180), "y": (-180, 180), "z": (-180, 180)}, False),
    "spine": ("YXZ", {"x": (-35, 35), "y": (-25, 80), "z": (-45, 45)}, True),
    "cervical": ("YXZ", {"x": (-45, 45), "y": (-45, 45), "z": (-60, 60)}, True),
    "pelvic_girdle": ("YXZ", {"x": (-5, 5), "y": (-5, 5), "z": (-5, 5)}, True),
    "hip": ("YXZ", {"x": (-30, 45), "y": (-120, 30), "z": (-45, 45)}, False),
    "knee": ("YXZ", {"x": (-5, 5), "y": (-10, 135), "z": (-30, 40)}, False),
    "ankle": ("YXZ", {"x": (-35, 15), "y": (-40, 50), "z": (-20, 10)}, False),
    "toe": ("YXZ", {"x": (-5, 5), "y": (-70, 45), "z": (-5, 5)}, False),
    "shoulder_girdle": ("XZY", {"x": (-10, 45), "y": (-30, 30), "z": (-15, 30)}, True),
    "shoulder": ("XZY", {"x": (-120, 90), "y": (-90, 70), "z": (-135, 45)}, False),
    "elbow": ("ZXY", {"x": (-5, 5), "y": (-80, 80), "z": (-150, 10)}, True),
    "wrist": ("XZY", {"x": (-80, 70), "y": (-20, 20), "z": (-20, 30)}, False),
}
"""Why these Euler orders: the first angle has the full circle and the middle one only
[-90, 90] (at +-90 the first and last axes align). Legs, spine and neck flex first (Y) and
keep abduction/lateral bending (X, always small) in the middle; the elbow flexes first (Z);
shoulder, girdle and wrist elevate first (X) with the horizontal swing in the middle, so the
singular direction is the arm pointing straight forward or back, not the common arm-at-side
pose. ``elbow`` is shared because some rigs put a forearm-twist joint on the chain."""


def euler_order(role: str) -> str:
    """Intrinsic scipy Euler order (e.g. ``"YXZ"``) of the hinges of a joint of ``role``."""
    return ROLE_TABLE[role][0]


def is_shared(role: str) -> bool:
    """Whether consecutive joints of ``role`` form one anatomical joint (spine, neck...)."""
    return ROLE_TABLE[role][2]


def joint_ranges(role: str, side: str) -> dict[str, tuple[float, float]]:
    """Hinge ranges in radians, ``{axis: (lo, hi)}``, of one joint of ``role`` (for a shared
    role also the range of the chain's total, see the module).

    Args:
        role: a key of :data:`ROLE_TABLE`.
        side: ``"left"``, ``"right"`` or ``"center"`` (centre joints use the left ranges,
            which are symmetric for every centre role).
    """
    _, degrees, _ = ROLE_TABLE[role]
    out = {}
    for axis, (lo, hi) in degrees.items():
        if side == "right" and axis in ("x", "z"):
            lo, hi = -hi, -lo
        out[axis] = (float(np.radians(lo)), float(np.radians(hi)))
    return out

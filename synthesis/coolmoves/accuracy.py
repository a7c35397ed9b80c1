"""Foot skating of a CoolMoves output (its stance feet pinned or not, :mod:`.foot_contact`).

Accuracy against the ground truth (body17 errors, hand correlation) is method-independent
and lives in :mod:`synthesis.scoring`.
"""

from __future__ import annotations

from avatarsim.avatar_models import Motion, body17
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.synthesis.coolmoves import foot_contact

_ANKLES = ("l_ankle", "r_ankle")


def stance_skating_cm_s(output: Motion, standing_ankle_z: float) -> float:
    """Mean horizontal ankle speed (cm/s) over the frames where ``output``'s own ankles are in
    contact (:func:`~.foot_contact.contacts`, the UHC/PhysDiff height and velocity test against
    the ankles' standing height ``standing_ankle_z``, e.g.
    :attr:`CoolMoves.standing_ankle_height`)."""
    ankles = body17_positions(output)[:, body17.group_indices(_ANKLES)]
    contact = foot_contact.contacts(ankles, standing_ankle_z, output.fps)
    return foot_contact.skating_cm_s(ankles, contact, output.fps)

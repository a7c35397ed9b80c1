"""CoolMoves (Ahuja et al., IMWUT 2021): full-body motion accentuation from a VR headset and two
controllers, by nearest-neighbour matching of 100 ms hand windows into a stylised database.

One concept per module: :mod:`.features` (windows, features, speed augmentation),
:mod:`.correlation` (hand-foot Pearson filter), :mod:`.database`, :mod:`.knn`, :mod:`.gmm`
(the mixture-model matcher: the variant is ``CoolMoves`` with ``Options(matcher="gmm")``),
:mod:`.alignment`, :mod:`.blend`, :mod:`.smoothing`, :mod:`.limits`, :mod:`.foot_contact`
(with the two-bone limb solver shared by the methods, :mod:`synthesis.two_bone`),
:mod:`.synthesizer` (the method as a :class:`~synthesis.base.Synthesizer`),
:mod:`.applications` (§5, run from Python: see the README) and :mod:`.accuracy` (foot
skating of the output). Accuracy against the ground truth
is :mod:`synthesis.scoring`.
"""

from avatarsim.synthesis.coolmoves.database import (
    FEET_DRIVE,
    HANDS_DRIVE,
    Database,
    Drivers,
    build_database,
)
from avatarsim.synthesis.coolmoves.synthesizer import CoolMoves, Options

__all__ = [
    "FEET_DRIVE",
    "HANDS_DRIVE",
    "CoolMoves",
    "Database",
    "Drivers",
    "Options",
    "build_database",
]

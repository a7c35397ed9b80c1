"""AvatarGo (shared/papers/avatargo.txt §3): a self-avatar from a headset, two controllers
and three Vive trackers.

One concept per module: :mod:`.calibration` (Walk-In-Avatar roles and eye height, §3.2),
:mod:`.offsets` (exact tracker offsets, eqs. 2-3, and the fixed baseline), :mod:`.spine`
(eqs. 1, 4), :mod:`.hands` (palm over the controller, reach), :mod:`.fingers` (finger IK,
eqs. 5-7), :mod:`.synthesizer` (the ``AvatarGo`` Synthesizer) and :mod:`.study` (simulated
users, §4-5).
"""

from avatarsim.synthesis.avatargo.calibration import (
    CalibrationError,
    MissingDeviceError,
    NotTPoseError,
    SwappedTrackersError,
)
from avatarsim.synthesis.avatargo.synthesizer import AvatarGo

__all__ = [
    "AvatarGo",
    "CalibrationError",
    "MissingDeviceError",
    "NotTPoseError",
    "SwappedTrackersError",
]

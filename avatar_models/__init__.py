"""Who moves: skeletons, motions, rigs, formats, the motion library and generator, the body."""

from avatar_models.errors import (
    AvatarsimError,
    MotionFormatError,
    MotionValueError,
    RigError,
    UnknownJointError,
)
from avatar_models.motion import Motion
from avatar_models.skeleton import Skeleton

__all__ = [
    "AvatarsimError",
    "Motion",
    "MotionFormatError",
    "MotionValueError",
    "RigError",
    "Skeleton",
    "UnknownJointError",
]

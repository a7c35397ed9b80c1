"""Who moves: skeletons, motions, rigs, formats, the motion library and generator, the body."""

import os

# The one place that picks the headless OpenGL backend, before mujoco or pyrender is imported
# anywhere (every package imports avatar_models first). EGL by default; a user may set
# MUJOCO_GL=osmesa PYOPENGL_PLATFORM=osmesa where no EGL driver exists.
os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

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

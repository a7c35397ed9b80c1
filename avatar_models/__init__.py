"""Who moves: skeletons, motions, rigs, formats, the motion library and generator, the body."""

import ctypes.util
import os

# The one place that picks the headless OpenGL backend, before mujoco or pyrender is imported
# anywhere (every package imports avatar_models first): EGL by default, OSMesa where the
# system has no EGL library but has OSMesa. A user's MUJOCO_GL / PYOPENGL_PLATFORM win.
if "MUJOCO_GL" not in os.environ:
    no_egl = ctypes.util.find_library("EGL") is None
    os.environ["MUJOCO_GL"] = "osmesa" if no_egl and ctypes.util.find_library("OSMesa") else "egl"
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

from avatarsim.avatar_models.errors import (
    AvatarsimError,
    CalibrationError,
    MotionFormatError,
    MotionValueError,
    RigError,
    UnknownJointError,
)
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton

__all__ = [
    "AvatarsimError",
    "CalibrationError",
    "Motion",
    "MotionFormatError",
    "MotionValueError",
    "RigError",
    "Skeleton",
    "UnknownJointError",
]

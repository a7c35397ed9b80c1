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
from avatarsim.avatar_models.lazy_exports import lazy_exports
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton

# Loaded on first use (formats and the generator import more than a bare ``import`` needs).
_EXPORTS = {
    "load_motion": ".formats",
    "save_motion": ".formats",
    "ACTIVITIES": ".generator",
    "generate": ".generator",
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)


__all__ = [
    *_EXPORTS,
    "AvatarsimError",
    "CalibrationError",
    "Motion",
    "MotionFormatError",
    "MotionValueError",
    "RigError",
    "Skeleton",
    "UnknownJointError",
]

"""Typed exceptions shared by every avatarsim package.

Every error a user can cause (bad file, bad stream, unknown joint, wrong unit) derives from
:class:`AvatarsimError`; the CLI maps these to exit code 2 with a one-line reason.
"""

from __future__ import annotations

from pathlib import Path


class AvatarsimError(Exception):
    """Base class for user-facing errors (bad input, not a bug)."""


class MotionFormatError(AvatarsimError):
    """A motion file is malformed. Carries the path and (1-based) line when known."""

    def __init__(self, message: str, path: str | Path | None = None, line: int | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        where = ""
        if self.path is not None:
            where = self.path if line is None else f"{self.path}:{line}"
            where += ": "
        super().__init__(f"{where}{message}")
        self.reason = message


class UnknownJointError(AvatarsimError, KeyError):
    """A joint name that the skeleton or rig does not have."""

    def __init__(self, name: str, available: list[str] | tuple[str, ...]):
        self.name = name
        shown = ", ".join(list(available)[:12]) + (" ..." if len(available) > 12 else "")
        super().__init__(f"unknown joint {name!r}; this skeleton has: {shown}")

    def __str__(self) -> str:  # KeyError would repr() the message
        return self.args[0]


class RigError(AvatarsimError):
    """A rig description file is invalid, or no rig matches a skeleton."""


class CalibrationError(AvatarsimError, ValueError):
    """A calibration that its input cannot identify: too few checkerboard views of a camera,
    a failed solve, a walk-in sample that does not tell the trackers apart. The message says
    what to fix."""


class MotionValueError(AvatarsimError, ValueError):
    """Motion data with impossible values: NaN, zero frames, wrong shapes, bad fps or units."""

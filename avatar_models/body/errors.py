"""The body package's typed errors."""

from __future__ import annotations

from avatarsim.avatar_models.errors import AvatarsimError


class BodyError(AvatarsimError, ValueError):
    """A body cannot be built: unknown skeleton, impossible height, mass or segment scale."""


class RestPoseNotUprightError(BodyError):
    """The skeleton's rest pose does not stand (head not above the ankles, Z up), so no body
    can be laid out in its rest frame; a caller can retarget the motion onto a rig that does
    (e.g. Bandai's rig, whose rest pose lies along local X)."""

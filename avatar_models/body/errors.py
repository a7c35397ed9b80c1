"""The body package's typed error."""

from __future__ import annotations

from avatar_models.errors import AvatarsimError


class BodyError(AvatarsimError, ValueError):
    """A body cannot be built: unknown skeleton, impossible height, mass or segment scale."""

"""How a full body is inferred from sparse signals: one module (or subpackage) per method, each
a :class:`~synthesis.base.Synthesizer` (one core over a batch of frames, ``advance``; streaming
``reset``/``step`` and batch ``run`` both call it). :mod:`synthesis.scoring` runs and scores
any of them; :mod:`synthesis.evaluate` holds the accuracy protocols."""

from avatarsim.avatar_models.lazy_exports import lazy_exports
from avatarsim.synthesis.base import (
    FrameBatch,
    Pose,
    Poses,
    SynthesisError,
    Synthesizer,
    TrackingFrame,
    on_clock,
    usable_mask,
)

# The method registry builds every method (torch among them): loaded on first use.
_EXPORTS = {"METHODS": ".methods", "MethodInputs": ".methods", "build": ".methods"}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

__all__ = [
    *_EXPORTS,
    "FrameBatch",
    "Pose",
    "Poses",
    "SynthesisError",
    "Synthesizer",
    "TrackingFrame",
    "on_clock",
    "usable_mask",
]

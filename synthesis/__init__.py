"""How a full body is inferred from sparse signals: one module (or subpackage) per method, each
a :class:`~synthesis.base.Synthesizer` (one core over a batch of frames, ``advance``; streaming
``reset``/``step`` and batch ``run`` both call it). :mod:`synthesis.scoring` runs and scores
any of them; :mod:`synthesis.evaluate` holds the accuracy protocols."""

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

__all__ = [
    "FrameBatch",
    "Pose",
    "Poses",
    "SynthesisError",
    "Synthesizer",
    "TrackingFrame",
    "on_clock",
    "usable_mask",
]

"""How a full body is inferred from sparse signals: one module (or subpackage) per method, each
a :class:`~synthesis.base.Synthesizer` (streaming ``reset``/``step``, batch ``run``)."""

from synthesis.base import (
    Pose,
    SynthesisError,
    Synthesizer,
    TrackingFrame,
    on_clock,
    usable_mask,
)

__all__ = ["Pose", "SynthesisError", "Synthesizer", "TrackingFrame", "on_clock", "usable_mask"]

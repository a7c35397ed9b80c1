"""Scenario stages. Each module has ``METRICS`` (name -> meaning) and ``run(ctx)``; the order
of :data:`STAGES` is the data flow of ARCHITECTURE.md."""

from avatarsim.scripts.stages import (
    body,
    cameras,
    control,
    devices,
    motion,
    physics,
    pictures,
    synthesis,
)

STAGES = (motion, body, physics, control, devices, synthesis, cameras, pictures)

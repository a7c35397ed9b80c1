"""Scenario stages. Each module has ``METRICS`` (name -> meaning) and ``run(ctx)``; the order
of :data:`STAGES` is the data flow of ARCHITECTURE.md."""

from scripts.stages import (
    body,
    cameras,
    devices,
    motion,
    physics,
    pictures,
    synthesis,
    tracking,
)

STAGES = (motion, body, physics, tracking, devices, synthesis, cameras, pictures)

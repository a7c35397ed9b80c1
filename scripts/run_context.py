"""What the stages of a scenario run share: inputs, intermediate results, metrics, outputs."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console

from avatar_models.motion import Motion
from scripts.results import ThresholdResult
from scripts.scenario import Scenario
from sim.humanoid import Humanoid


@dataclass
class RunContext:
    """Filled stage by stage. ``motion`` is the ground truth; ``humanoid`` its body, built
    once (stage ``body``) and used by every later stage. ``metrics`` are thresholded by
    ``[thresholds]``; ``checks`` hold rows a stage judged itself (e.g. physics checks with
    their own thresholds)."""

    scenario: Scenario
    out_dir: Path
    console: Console
    motion: Motion | None = None
    humanoid: Humanoid | None = None
    artifacts: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, float] = field(default_factory=dict)
    checks: list[ThresholdResult] = field(default_factory=list)
    info: dict[str, Any] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)

    def output(self, key: str, path: Path) -> Path:
        """Record a written file under ``key`` (relative to the output folder)."""
        self.outputs[key] = str(Path(path).relative_to(self.out_dir))
        return Path(path)

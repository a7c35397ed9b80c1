"""The ``Check`` protocol: one physics check over a whole replay, and what it returns.

Shapes: ``T`` frames. A check reads a :class:`~sim.checks.replay.BodyReplay` (the motion
replayed on the humanoid, with shared derived quantities such as foot contacts) and returns
per-frame columns for the CSV, clip values for the JSON, and the frames it finds at fault.
Pass/fail is decided in one place (:mod:`sim.plausibility`) against :mod:`sim.thresholds`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from avatarsim.sim.thresholds import CheckConfig

if TYPE_CHECKING:
    from avatarsim.sim.checks.replay import BodyReplay


@dataclass(frozen=True)
class CheckResult:
    """What one check found.

    Attributes:
        name: the check's name.
        per_frame: column name -> ``(T,)`` array (NaN where undefined, e.g. no contact).
        values: clip value name -> number (contract keys among them, see
            :data:`sim.thresholds.THRESHOLD_KEYS`).
        flagged: ``(T,)`` bool, frames this check finds at fault.
        details: anything a person needs to act on it (worst hinges, colliding pairs...).
    """

    name: str
    per_frame: dict[str, np.ndarray]
    values: dict[str, float]
    flagged: np.ndarray
    details: dict[str, Any] = field(default_factory=dict)


class Check(Protocol):
    """A physics check: ``check(replay, config) -> CheckResult``."""

    name: str

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult: ...

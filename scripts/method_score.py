"""A synthesis method scored end to end: accuracy and speed (:func:`synthesis.scoring.score_run`)
plus the physics of its output on the humanoid (:func:`sim.plausibility.check_humanoid`).

Composed here because ``sim`` and ``synthesis`` never import each other. The physics check
uses the caller's :class:`~sim.thresholds.CheckConfig`, i.e. a scenario's ``[physics]``
settings, so a method's output is judged by the same definitions as the ground truth.
"""

from __future__ import annotations

from dataclasses import dataclass

from avatarsim.avatar_models import Motion
from avatarsim.render_cams import TrackingStream
from avatarsim.sim.humanoid import Humanoid, humanoid_for
from avatarsim.sim.plausibility import check_humanoid
from avatarsim.sim.thresholds import CheckConfig
from avatarsim.synthesis.base import Synthesizer
from avatarsim.synthesis.scoring import MethodScore, score_run


@dataclass(frozen=True, eq=False)
class MethodResult:
    """A method's score, its output on the humanoid and the physics check values (the
    keys of :data:`sim.plausibility.CONTRACT_KEYS`, e.g. ``penetration_cm_p95``)."""

    score: MethodScore
    humanoid: Humanoid
    physics: dict[str, float]


def score_method(
    synth: Synthesizer,
    truth: Motion,
    stream: TrackingStream,
    checks: CheckConfig,
    time_steps: bool = False,
) -> MethodResult:
    """Run, score and physics-check ``synth`` on ``stream`` sampled from ``truth``."""
    score = score_run(synth, truth, stream, time_steps)
    humanoid = humanoid_for(score.output)
    return MethodResult(score, humanoid, check_humanoid(humanoid, checks).values)

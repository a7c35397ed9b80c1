"""``check_humanoid`` / ``check_motion``: replay a motion on the humanoid and run every
physics check on it. The humanoid comes from :func:`sim.humanoid.humanoid_for`, the one place
that decides whether a rig is retargeted.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import mujoco
import numpy as np

from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.motion import Motion
from avatarsim.sim.checks import ALL_CHECKS, BodyReplay, Check, CheckResult
from avatarsim.sim.humanoid import Humanoid, humanoid_for
from avatarsim.sim.thresholds import THRESHOLD_KEYS, CheckConfig

CONTRACT_KEYS = (
    "penetration_cm_p95",
    "float_cm_p95",
    "skate_cm_s_median",
    "joint_limit_violation_frac",
    "self_collision_frac",
    "residual_force_bw_p95",
)


@dataclass(frozen=True, eq=False)
class PlausibilityReport:
    """All check results of one motion.

    Attributes:
        results: one :class:`CheckResult` per check, in run order.
        config: the definitions and thresholds used.
        fps: frames per second of the motion.
        meta: provenance (rig, frames, body mass, the motion's own meta keys that are scalars).
    """

    results: tuple[CheckResult, ...]
    config: CheckConfig
    fps: float
    meta: dict[str, Any] = field(default_factory=dict)

    @cached_property
    def values(self) -> dict[str, float]:
        """Every clip value of every check."""
        return {k: v for r in self.results for k, v in r.values.items()}

    @cached_property
    def thresholds(self) -> list[dict[str, Any]]:
        """``[{name, check, value, threshold, passed}]`` for every thresholded value."""
        rows = []
        for key, check in THRESHOLD_KEYS.items():
            if key in self.values:
                value, limit = self.values[key], getattr(self.config, key)
                rows.append(
                    dict(
                        name=key,
                        check=check,
                        value=float(value),
                        threshold=float(limit),
                        passed=bool(value <= limit),
                    )
                )
        return rows

    @property
    def failed_checks(self) -> list[str]:
        return list(dict.fromkeys(row["check"] for row in self.thresholds if not row["passed"]))

    @property
    def passed(self) -> bool:
        return not self.failed_checks

    def flagged(self, check: str) -> bool:
        """Whether ``check`` (a check name) failed its threshold."""
        return check in self.failed_checks

    def contract(self) -> dict[str, Any]:
        """The ``avatarsim check`` JSON: contract keys, then ``passed``, then the rest."""
        out: dict[str, Any] = {k: self.values.get(k, 0.0) for k in CONTRACT_KEYS}
        out["passed"] = self.passed
        out["checks"] = self.thresholds
        out["values"] = self.values
        out["details"] = {r.name: r.details for r in self.results if r.details}
        out["config"] = self.config.as_dict()
        out["meta"] = self.meta
        return out

    def per_frame(self) -> dict[str, np.ndarray]:
        """Columns ``time_s``, then every check's per-frame columns, then ``flag_<check>``."""
        n = len(self.results[0].flagged)
        columns: dict[str, np.ndarray] = {"frame": np.arange(n), "time_s": np.arange(n) / self.fps}
        for r in self.results:
            columns.update(r.per_frame)
        for r in self.results:
            if r.flagged.any():
                columns[f"flag_{r.name}"] = r.flagged.astype(int)
        return columns


def check_qpos(
    body: BodyDescription,
    qpos: np.ndarray,
    fps: float,
    config: CheckConfig | None = None,
    checks: Sequence[Check] = ALL_CHECKS,
    model: mujoco.MjModel | None = None,
) -> PlausibilityReport:
    """Run ``checks`` on ``qpos (T, nq)`` of ``body`` (e.g. a physics control result)."""
    config = config or CheckConfig()
    model = model or body.model
    replay = BodyReplay.run(body, model, qpos, fps, config)
    meta = {"rig": body.rig.name, "frames": int(qpos.shape[0]), "fps": float(fps)}
    meta["body_mass_kg"] = body.mass_kg
    return PlausibilityReport(tuple(c(replay, config) for c in checks), config, fps, meta)


def check_humanoid(
    humanoid: Humanoid,
    config: CheckConfig | None = None,
    checks: Sequence[Check] = ALL_CHECKS,
) -> PlausibilityReport:
    """Run ``checks`` on the motion of ``humanoid`` (:func:`sim.humanoid.humanoid_for`);
    the report's meta holds the retargeting summary and the motion's scalar meta."""
    h = humanoid
    report = check_qpos(h.body, h.qpos, h.motion.fps, config, checks, model=h.model)
    scalars = {k: v for k, v in h.motion.meta.items() if isinstance(v, str | int | float | bool)}
    report.meta.update(scalars | h.summary())
    return report


def check_motion(
    motion: Motion,
    body: BodyDescription | None = None,
    config: CheckConfig | None = None,
    checks: Sequence[Check] = ALL_CHECKS,
) -> PlausibilityReport:
    """Replay ``motion`` on ``body`` (a motion on that body's own skeleton), or on the
    humanoid :func:`sim.humanoid.humanoid_for` gives when ``None``, and run ``checks`` with
    ``config`` (defaults: :class:`CheckConfig`).

    Raises:
        MotionValueError: non-finite motion.
        BodyError: a motion not on ``body``'s skeleton; see :func:`sim.humanoid.humanoid_for`.
    """
    if not (np.all(np.isfinite(motion.root_pos)) and np.all(np.isfinite(motion.local_rot))):
        raise MotionValueError("motion has NaN/inf values")
    if body is None:
        return check_humanoid(humanoid_for(motion), config, checks)
    return check_qpos(body, body.qpos_from_motion(motion), motion.fps, config, checks)

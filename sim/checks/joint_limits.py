"""Joint-limit violations: hinges beyond the body's anatomical ranges (degrees).

The hinge angles are the motion's exact qpos (:meth:`BodyDescription.qpos_from_motion`), the
ranges MuJoCo's ``jnt_range`` (the body's AAOS ranges). A frame violates when any hinge is
beyond its range by more than ``limit_tolerance_deg``. Hinges whose whole range is narrower
than ``limit_min_range_deg`` are not checked: they are the small allowances the body gives
degrees of freedom a joint does not have anatomically (knee and elbow varus/valgus, pelvic
girdle) so that replay stays exact, and the skeleton fitting of real mocap puts its error
(and the elbow's carrying angle) there.
"""

from __future__ import annotations

import mujoco
import numpy as np

from sim.checks.base import CheckResult
from sim.checks.replay import BodyReplay
from sim.thresholds import CheckConfig


class JointLimits:
    name = "joint_limits"

    def __call__(self, replay: BodyReplay, config: CheckConfig) -> CheckResult:
        model = replay.model
        width = np.degrees(np.diff(model.jnt_range, axis=1)[:, 0])
        hinge = model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE
        hinges = np.flatnonzero(hinge & (width >= config.limit_min_range_deg))
        angle = replay.qpos[:, model.jnt_qposadr[hinges]]  # (T, H)
        lo, hi = model.jnt_range[hinges].T
        excess = np.degrees(np.maximum(np.maximum(lo - angle, angle - hi), 0.0))  # (T, H)
        worst = excess.max(axis=1) if hinges.size else np.zeros(replay.n_frames)
        violating = excess > config.limit_tolerance_deg
        names = [model.joint(j).name for j in hinges]
        per_hinge = {
            names[h]: {"frames": int(violating[:, h].sum()), "max_deg": float(excess[:, h].max())}
            for h in np.flatnonzero(violating.any(axis=0))
        }
        return CheckResult(
            name=self.name,
            per_frame={"limit_excess_deg": worst},
            values={
                "joint_limit_violation_frac": float(violating.any(axis=1).mean()),
                "limit_excess_deg_max": float(worst.max()),
            },
            flagged=violating.any(axis=1),
            details={"violations": per_hinge},
        )

"""Physics checks, one module per check around the :class:`~sim.checks.base.Check` protocol.

:data:`ALL_CHECKS` lists them in report order; adding a check means adding a module and a
line here (and its definition and threshold in :mod:`sim.thresholds`).
"""

from sim.checks.base import Check, CheckResult
from sim.checks.contact import FootContactCheck
from sim.checks.floating import FloatingCheck
from sim.checks.jitter import JitterCheck
from sim.checks.joint_limits import JointLimitCheck
from sim.checks.penetration import PenetrationCheck
from sim.checks.replay import BodyReplay
from sim.checks.residual import ResidualForceCheck
from sim.checks.self_collision import SelfCollisionCheck
from sim.checks.skating import SkatingCheck
from sim.checks.support import BalanceCheck

ALL_CHECKS: tuple[Check, ...] = (
    FootContactCheck(),
    PenetrationCheck(),
    FloatingCheck(),
    SkatingCheck(),
    JointLimitCheck(),
    SelfCollisionCheck(),
    JitterCheck(),
    BalanceCheck(),
    ResidualForceCheck(),
)

__all__ = ["ALL_CHECKS", "BodyReplay", "Check", "CheckResult"]

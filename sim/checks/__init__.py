"""Physics checks, one module per check around the :class:`~sim.checks.base.Check` protocol.

:data:`ALL_CHECKS` lists them in report order; adding a check means adding a module and a
line here (and its definition and threshold in :mod:`sim.thresholds`).
"""

from avatarsim.sim.checks.base import Check, CheckResult
from avatarsim.sim.checks.contact import FootContactCheck
from avatarsim.sim.checks.floating import FloatingCheck
from avatarsim.sim.checks.jitter import JitterCheck
from avatarsim.sim.checks.joint_limits import JointLimitCheck
from avatarsim.sim.checks.penetration import PenetrationCheck
from avatarsim.sim.checks.replay import BodyReplay
from avatarsim.sim.checks.residual import ResidualForceCheck
from avatarsim.sim.checks.self_collision import SelfCollisionCheck
from avatarsim.sim.checks.skating import SkatingCheck
from avatarsim.sim.checks.support import BalanceCheck

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

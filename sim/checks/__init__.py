"""Physics checks, one module per check around the :class:`~sim.checks.base.Check` protocol.

:data:`ALL_CHECKS` lists them in report order; adding a check means adding a module and a
line here (and its definition and threshold in :mod:`sim.thresholds`).
"""

from sim.checks.base import Check, CheckResult
from sim.checks.contact import FootContact
from sim.checks.floating import Floating
from sim.checks.jitter import Jitter
from sim.checks.joint_limits import JointLimits
from sim.checks.penetration import Penetration
from sim.checks.replay import BodyReplay
from sim.checks.residual import ResidualForce
from sim.checks.self_collision import SelfCollision
from sim.checks.skating import Skating
from sim.checks.support import Balance

ALL_CHECKS: tuple[Check, ...] = (
    FootContact(),
    Penetration(),
    Floating(),
    Skating(),
    JointLimits(),
    SelfCollision(),
    Jitter(),
    Balance(),
    ResidualForce(),
)

__all__ = ["ALL_CHECKS", "BodyReplay", "Check", "CheckResult"]

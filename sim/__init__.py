"""The MuJoCo humanoid and its physics checks, control and reports.

``avatar_models`` is imported first because it picks the headless GL backend (``MUJOCO_GL``)
before anything here imports mujoco (:mod:`sim.render` renders offscreen). The public names
below load their modules on first use (:mod:`avatar_models.lazy_exports`)."""

import avatarsim.avatar_models  # noqa: F401
from avatarsim.avatar_models.lazy_exports import lazy_exports

_EXPORTS = {
    "Humanoid": ".humanoid",
    "humanoid_for": ".humanoid",
    "CheckConfig": ".thresholds",
    "PlausibilityReport": ".plausibility",
    "check_humanoid": ".plausibility",
    "check_motion": ".plausibility",
    "check_qpos": ".plausibility",
    "Controller": ".control.controller",
    "ControlResult": ".control.controller",
    "ControlSettings": ".control.settings",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

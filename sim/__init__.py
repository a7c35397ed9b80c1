"""The MuJoCo humanoid and its physics checks, control and reports.

``avatar_models`` is imported first because it picks the headless GL backend (``MUJOCO_GL``)
before anything here imports mujoco (:mod:`sim.render` renders offscreen)."""

import avatarsim.avatar_models  # noqa: F401

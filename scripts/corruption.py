"""A scenario's ``motion.corrupt``: the ground truth made physically wrong in one known way
(``sim.corrupt``), so a suite can prove that the physics check for that defect fires.

Each defect uses ``sim.corrupt``'s default size, which ``tests/sim/test_corrupt.py`` shows its
check flags on walks, runs, squats and CMU clips.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.motion import Motion
from avatarsim.scripts.scenario import CORRUPTIONS
from avatarsim.sim import corrupt
from avatarsim.sim.plausibility import check_motion


def corrupted(motion: Motion, defect: str, seed: int) -> Motion:
    """``motion`` with ``defect`` (one of :data:`scripts.scenario.CORRUPTIONS`)."""
    if defect not in CORRUPTIONS:
        raise ValueError(f"unknown corruption {defect!r}; known: {CORRUPTIONS}")
    if defect == "sink_feet":
        return corrupt.sink_feet(motion)
    if defect == "float_body":
        return corrupt.float_body(motion)
    if defect == "add_jitter":
        return corrupt.add_jitter(motion, np.random.default_rng(seed))
    body = build_body(motion.skeleton)
    if defect == "bend_knee":
        return corrupt.bend_knee(motion, body)
    # inject_sliding: the left foot slides during its stances, found on the clean motion.
    stance = check_motion(motion, body).per_frame()["contact_left"] > 0
    return corrupt.inject_sliding(motion, stance)

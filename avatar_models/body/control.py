"""The physics-control variant of a body's model, derived from its spec (not by editing a
compiled model).

Physics control computes joint torques itself, so the variant's actuators are motors
(``ctrl`` is the torque: gain 1, no bias, no control clamp). Only the floor collides with the
body: the retargeted limbs of real clips overlap (upper arms 4 cm into the chest, calves
crossing), and contacts between them would push with forces the controller does not know of.
Self-collision is a check on the reference (:mod:`sim.checks.self_collision`), not something
to simulate under physics control. Everything else (bodies, inertias, limits, sites) is the body's.
"""

from __future__ import annotations

import mujoco


def control_spec(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """A copy of ``spec`` (e.g. :attr:`BodyDescription.spec`) for physics control (module
    docstring); ``spec`` itself is left as it is. Compile it with ``.compile()``."""
    out = spec.copy()
    for actuator in out.actuators:
        # Position actuators already have a fixed gain and an affine bias; zero parameters
        # make the affine bias vanish.
        actuator.gainprm = [1.0] + [0.0] * (len(actuator.gainprm) - 1)
        actuator.biasprm = [0.0] * len(actuator.biasprm)
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for geom in out.geoms:
        on_world = geom.parent.id == out.worldbody.id
        # contype/conaffinity: a pair collides when one's type meets the other's affinity,
        # so world geoms (type 0, affinity 1) meet body geoms (type 1, affinity 0) only.
        geom.contype = 0 if on_world else 1
        geom.conaffinity = 1 if on_world else 0
    return out

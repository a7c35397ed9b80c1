"""Ankle torques of a body held leaning 4 degrees forward against what statics demands
(tests/sim/test_tracking.py).

    .venv/bin/python -m tests.measurements.lean_statics
"""

from __future__ import annotations

import mujoco
import numpy as np

from avatar_models.body import build_body
from avatar_models.body.ik import humanoid_model
from avatar_models.generator import generate, sample_subject
from avatar_models.rigs import load_rig
from sim.soles import foot_bodies
from sim.tracking import track
from tests.sim.test_tracking import _leaning


def ankle_balance(body, degrees: float = 4.0) -> list[tuple[float, float]]:
    """(demanded, supplied) ankle-line moment (N m) at frames 40, 50, 60."""
    model = humanoid_model(body)
    result = track(model, body.qpos_from_motion(_leaning(body, degrees)), 30.0)
    data = mujoco.MjData(model)
    feet = [model.body(name).id for name in foot_bodies(model)]
    at_ankle = [k for k, j in enumerate(model.actuator_trnid[:, 0]) if model.jnt_bodyid[j] in feet]
    mass, foot_mass = model.body_subtreemass[0], model.body_subtreemass[feet]
    out = []
    for t in (40, 50, 60):
        data.qpos[:] = result.qpos[t]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        com = (mass * data.subtree_com[0] - foot_mass @ data.subtree_com[feet]) / (
            mass - foot_mass.sum()
        )
        left, right = (data.xanchor[model.body_jntadr[f]] for f in feet)
        u = (left - right) / np.linalg.norm(left - right)
        demanded = np.cross(com - left, [0.0, 0.0, -(mass - foot_mass.sum()) * 9.81]) @ u
        supplied = result.torque[t, at_ankle] @ (data.xaxis[model.actuator_trnid[at_ankle, 0]] @ u)
        out.append((round(float(demanded), 2), round(float(supplied), 2)))
    return out


def main() -> None:
    print("default", ankle_balance(build_body(load_rig("avatar").skeleton)))
    rng = np.random.default_rng(5)
    for i in range(3):
        skeleton = generate("walk", sample_subject(rng), 0.1, 30.0).skeleton
        print(f"sampled {i}", ankle_balance(build_body(skeleton)))


if __name__ == "__main__":
    main()

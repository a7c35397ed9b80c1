"""The humanoid: body from the motion's skeleton, its MJCF, the exact qpos, replay exactness."""

from __future__ import annotations

import mujoco
import numpy as np

from avatar_models.body import build_body
from scripts.results import write_atomic
from scripts.run_context import RunContext
from sim.replay import replay_kinematic

DEFAULT_MASS_KG = 75.0

METRICS = {
    "replay_error_mm_max": "max distance between MuJoCo's replayed joints and the motion's FK",
}


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.body
    subject = ctx.motion.meta.get("subject") or {}
    mass_kg = spec.mass_kg or subject.get("mass_kg", DEFAULT_MASS_KG)
    ctx.body = build_body(ctx.motion.skeleton, height_m=spec.height_m, mass_kg=mass_kg)
    xml = ctx.body.to_mjcf()
    ctx.model = mujoco.MjModel.from_xml_string(xml)
    ctx.qpos = ctx.body.qpos_from_motion(ctx.motion)
    ctx.output("mjcf", write_atomic(ctx.out_dir / "humanoid.xml", xml))

    # Exactness of the pose -> qpos mapping: MuJoCo's bodies against the motion's FK.
    trace = replay_kinematic(ctx.model, ctx.qpos)
    sk = ctx.motion.skeleton
    names = [
        mujoco.mj_id2name(ctx.model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(ctx.model.nbody)
    ]
    pairs = np.array([(sk.index(n), b) for b, n in enumerate(names) if n in sk])
    fk = ctx.motion.global_positions()[:, pairs[:, 0]]
    err = np.linalg.norm(trace.body_pos[:, pairs[:, 1]] - fk, axis=-1)
    ctx.metrics["replay_error_mm_max"] = float(err.max() * 1000.0)
    ctx.info["body"] = {
        "mass_kg": mass_kg,
        "nq": ctx.model.nq,
        "nbody": ctx.model.nbody,
        "joints_compared": len(pairs),
    }

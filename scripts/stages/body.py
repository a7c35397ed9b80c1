"""The humanoid: built once for the ground truth by :func:`sim.humanoid.humanoid_for` (own rig:
exact qpos; any other rig: retargeted, residual reported), its MJCF, replay exactness."""

from __future__ import annotations

import mujoco
import numpy as np

from avatarsim.avatar_models.fileio import write_atomic
from avatarsim.avatar_models.formats import save_motion
from avatarsim.scripts.run_context import RunContext
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.replay import replay_kinematic

METRICS = {
    "replay_error_mm_max": "max distance between MuJoCo's replayed joints and the motion's FK",
    "retarget_residual_cm_mean": "mean body17 distance of the humanoid from a foreign rig's "
    "motion (0 on an own rig)",
}


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.body
    h = ctx.humanoid = humanoid_for(ctx.motion, height_m=spec.height_m, mass_kg=spec.mass_kg)
    if spec.height_m is not None:  # the ground truth at the body's height, saved as such
        ctx.motion = h.source
        ctx.output("motion_bvh", save_motion(ctx.motion, ctx.out_dir / "motion.bvh"))
        ctx.info["motion"]["height_m"] = spec.height_m
    ctx.output("mjcf", write_atomic(ctx.out_dir / "humanoid.xml", h.mjcf))

    # Exactness of the pose -> qpos mapping: MuJoCo's bodies against the motion's FK.
    trace = replay_kinematic(h.model, h.qpos)
    sk = h.motion.skeleton
    names = [mujoco.mj_id2name(h.model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(h.model.nbody)]
    pairs = np.array([(sk.index(n), b) for b, n in enumerate(names) if n in sk])
    fk = h.motion.global_positions()[:, pairs[:, 0]]
    err = np.linalg.norm(trace.body_pos[:, pairs[:, 1]] - fk, axis=-1)
    ctx.metrics["replay_error_mm_max"] = float(err.max() * 1000.0)
    ctx.metrics["retarget_residual_cm_mean"] = float(np.mean(h.residual_cm))
    ctx.info["body"] = h.summary() | {"nbody": h.model.nbody, "joints_compared": len(pairs)}

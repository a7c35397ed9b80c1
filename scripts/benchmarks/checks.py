"""Physics plausibility checking throughput, next to real time (90 Hz, a VR headset's rate).

Rows, all on one core in this process: the kinematic replay alone (``mj_kinematics`` +
``mj_collision`` per frame), every kinematic check (replay, contacts, penetration, floating,
skating, joint limits, self-collision, jitter, balance), and everything including the root
residual force (``mj_inverse`` per frame). Baseline: 90 frames/s, so the ratio reads as
"times real time". Motion: a built-in walk (60 s; 10 s with ``quick``).
"""

from __future__ import annotations

from pathlib import Path

from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.benchmarks import BenchRow, best_of
from avatarsim.sim.checks import ALL_CHECKS
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.plausibility import check_qpos
from avatarsim.sim.replay import replay_kinematic

REAL_TIME_HZ = 90.0


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    motion = generate("walk", duration_s=10.0 if quick else 60.0, fps=REAL_TIME_HZ)
    h = humanoid_for(motion)
    body, model, qpos = h.body, h.model, h.qpos
    n = len(qpos)
    kinematic = [c for c in ALL_CHECKS if c.name != "residual_force"]
    cases = {
        "replay_kinematic": lambda: replay_kinematic(model, qpos),
        "checks_kinematic": lambda: check_qpos(body, qpos, motion.fps, None, kinematic, model),
        "checks_all": lambda: check_qpos(body, qpos, motion.fps, None, ALL_CHECKS, model),
    }
    repeat = 2 if quick else 3
    return [
        BenchRow(
            name,
            "frames/s",
            n / best_of(fn, repeat),
            REAL_TIME_HZ,
            "real time (90 Hz)",
            f"{n} frames, {model.nbody - 1} bodies, {model.ngeom} geoms, one core",
        )
        for name, fn in cases.items()
    ]

"""How far the plain controller gets on built-in walks (tests/sim/control/test_controller.py).

    .venv/bin/python -m tests.measurements.walk_spread

16 walks of 2 s at 30 fps: seeds 0-7 on the default subject, then seeds 0-7 on 8 subjects of
``sample_subject(default_rng(123))``. Per walk: fall time, and the largest frame-wise mean
body17 distance (cm) over the first 1.0, 1.5 and 2.0 s.
"""

from __future__ import annotations

import json

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.sim.control.controller import control
from avatarsim.sim.control.model import control_model


def main() -> None:
    rng = np.random.default_rng(123)
    cases = [(None, s) for s in range(8)] + [(sample_subject(rng), s) for s in range(8)]
    for subject, seed in cases:
        walk = generate("walk", subject, duration_s=2.0, fps=30.0, seed=seed)
        body = build_body(walk.skeleton)
        r = control(control_model(body.spec), body.qpos_from_motion(walk), walk.fps)
        e = 100 * r.body17_error.mean(axis=1)
        row = {
            "height_m": None if subject is None else round(subject.height_m, 2),
            "seed": seed,
            "fall_s": r.fall_time_s,
            "max_cm_1s": round(e[:31].max(), 2),
            "max_cm_1.5s": round(e[:46].max(), 2),
            "max_cm_2s": round(e.max(), 2),
        }
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()

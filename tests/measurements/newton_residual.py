"""Newton residual of the whole body during a controlled built-in walk
(tests/sim/control/test_controller.py).

    .venv/bin/python -m tests.measurements.newton_residual 0 1 2 3

Per seed: |d(m v_com)/dt - (floor forces + m g)| per 2 ms step, in body weights.
"""

from __future__ import annotations

import sys

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.rigs import load_rig
from tests.sim.control.test_controller import newton_residual_bw


def main(seeds: list[int]) -> None:
    body = build_body(load_rig("avatar").skeleton)
    for seed in seeds:
        r = newton_residual_bw(body, 2.0, seed=seed)
        print(f"seed {seed}: mean {r.mean():.4f} p95 {np.percentile(r, 95):.4f} max {r.max():.4f}")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [0])

"""Ankle torques of a body held leaning 4 degrees forward against what statics demands
(tests/sim/control/test_qp.py).

    .venv/bin/python -m tests.measurements.lean_statics
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.rigs import load_rig
from tests.sim.control.test_qp import ankle_balance


def main() -> None:
    print("default", ankle_balance(build_body(load_rig("avatar").skeleton), 4.0)[1])
    rng = np.random.default_rng(5)
    for i in range(3):
        skeleton = generate("walk", sample_subject(rng), 0.1, 30.0).skeleton
        print(f"sampled {i}", ankle_balance(build_body(skeleton), 4.0)[1])


if __name__ == "__main__":
    main()

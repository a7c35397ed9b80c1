"""Jitter and skating values the checks give on clean motion (the ranges quoted in
sim/thresholds.py).

    .venv/bin/python -m tests.measurements.check_values [MOCAP_DIR] [--bandai]

Built-in activities on 3 subjects (default and two sampled) at 90 fps, 4 s; the 9 CMU clips
(frame 0, the T-pose, dropped) and 6 Bandai clips, whole; and 1 cm of root noise on the
built-in walk (90 fps).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.sim import corrupt
from avatarsim.sim.plausibility import check_motion

KEYS = ("jitter_m_s3_median", "skate_cm_s_median", "skate_slide_cm_max")
BANDAI = (
    "dataset-1/data/dataset-1_walk_normal_001.bvh",
    "dataset-1/data/dataset-1_run_normal_001.bvh",
    "dataset-1/data/dataset-1_punch_normal_001.bvh",
    "dataset-2/data/dataset-2_walk_normal_001.bvh",
    "dataset-2/data/dataset-2_run_normal_001.bvh",
    "dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh",
)


def row(name, motion, own_body: bool = True):
    body = build_body(motion.skeleton) if own_body else None  # None: retargeted (Bandai)
    values = check_motion(motion, body).values
    print(json.dumps({"clip": name, **{k: round(values[k], 1) for k in KEYS}}), flush=True)


def main(mocap: Path, only_bandai: bool = False) -> None:
    if only_bandai:
        for clip in BANDAI:
            row(f"bandai {Path(clip).stem}", load_motion(mocap / "bandai" / clip), False)
        return
    rng = np.random.default_rng(0)
    subjects = [None, sample_subject(rng), sample_subject(rng)]
    for i, subject in enumerate(subjects):
        for activity in ("walk", "run", "box", "squat", "wave", "kick", "lunge", "dribble"):
            row(f"builtin {activity} s{i}", generate(activity, subject, 4.0, 90.0, seed=i))
    walk = generate("walk", None, 4.0, 90.0, seed=0)
    row("builtin walk + 1 cm noise", corrupt.add_jitter(walk, np.random.default_rng(0), 0.01))
    for path in sorted((mocap / "cmu").glob("*.bvh")):
        row(f"cmu {path.stem}", load_motion(path)[1:])
    for clip in BANDAI:
        row(f"bandai {Path(clip).stem}", load_motion(mocap / "bandai" / clip), False)


if __name__ == "__main__":
    default = Path(__file__).resolve().parents[3] / "shared" / "mocap"
    args = [a for a in sys.argv[1:] if a != "--bandai"]
    main(Path(args[0]) if args else default, "--bandai" in sys.argv)

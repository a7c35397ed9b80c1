"""The hand-foot correlation filter (synthesis/coolmoves/correlation.py) per activity: mean
score and share of trials removed at the paper's threshold of 0.1 (CoolMoves §3.1.2).

    PYTHONPATH=. .venv/bin/python -m tests.measurements.hand_foot_correlation [MOCAP_DIR]

Generated: the paper's five activities plus walk, 5 subjects x 2 seeds (builtin_trials,
8 s). CMU: the clips of ``MOCAP_DIR/cmu`` by the activity CLIPS.md gives them (frame 0, the
T-pose, dropped). The paper: basketball and climbing above 0.5 on average, swimming below
0.2 (SD 0.18), nearly 60% of swimming removed at 0.1.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.formats import load_motion
from avatarsim.synthesis.coolmoves.correlation import CORRELATION_THRESHOLD, hand_foot_correlation
from avatarsim.synthesis.coolmoves.database import hands_and_feet
from avatarsim.synthesis.evaluate import builtin_trials

CMU_ACTIVITIES = {
    "06_06": "basketball",
    "102_01": "basketball",
    "13_33": "climbing",
    "14_33": "climbing",
    "125_01": "swimming",
    "126_01": "swimming",
    "09_01": "running",
    "16_35": "running",
    "35_17": "running",
}
"""CMU clip -> activity (``shared/mocap/cmu/CLIPS.md``)."""
GENERATED = ("box", "dribble", "climb_ladder", "run", "swim", "walk")


def generated_scores(seeds=(0, 1), subjects: int = 5) -> dict[str, list[float]]:
    out: dict[str, list[float]] = {}
    for seed in seeds:
        for trial in builtin_trials(GENERATED, subjects, 1, 8.0, seed):
            score = hand_foot_correlation(*hands_and_feet(trial.motion))
            out.setdefault(trial.cls, []).append(score)
    return out


def cmu_scores(folder: Path) -> dict[str, list[float]]:
    out: dict[str, list[float]] = {}
    for clip, activity in CMU_ACTIVITIES.items():
        motion = load_motion(folder / "cmu" / f"{clip}.bvh")[1:]
        out.setdefault(activity, []).append(hand_foot_correlation(*hands_and_feet(motion)))
    return out


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("../shared/mocap")
    tables = {"generated": generated_scores()}
    if (folder / "cmu").is_dir():
        tables["cmu"] = cmu_scores(folder)
    print(f"{'source':10} {'activity':14} {'trials':>6} {'mean':>6} {'sd':>5} {'removed':>8}")
    for source, scores in tables.items():
        for activity, values in scores.items():
            v = np.asarray(values)
            removed = float(np.mean(v < CORRELATION_THRESHOLD))
            print(
                f"{source:10} {activity:14} {v.size:6d} {v.mean():6.2f} {v.std():5.2f} "
                f"{removed:8.0%}"
            )


if __name__ == "__main__":
    main()

"""Physics tracking speed next to real time, and IK retargeting frames/s.

Rows: simulated seconds per wall second tracking the built-in walk (``sim.tracking``: a
whole-body QP every 5 simulation steps, 100 Hz; aim at least 10x real time), next to real time (1x);
retargeting frames/s (``sim.retarget``: body17 IK with mink) on a CMU clip from
``../shared/mocap`` (the built-in walk when that folder is absent), next to the clip's
own frame rate.
"""

from __future__ import annotations

import time
from pathlib import Path

from avatar_models.body import build_body
from avatar_models.body.ik import humanoid_model
from avatar_models.formats import load_motion
from avatar_models.generator import generate
from scripts.benchmarks import BenchRow, best_of
from sim.retarget import retarget
from sim.tracking import track

MOCAP_DIR = Path(__file__).resolve().parents[2].parent / "shared" / "mocap"
CMU_CLIP = "cmu/16_35.bvh"


def _tracking_row(quick: bool) -> BenchRow:
    seconds = 1.0 if quick else 3.0  # the walk stays upright for 3 s on every seed (tests)
    walk = generate("walk", duration_s=seconds, fps=30.0)
    body = build_body(walk.skeleton)
    qpos = body.qpos_from_motion(walk)
    wall = best_of(lambda: track(humanoid_model(body), qpos, walk.fps), 1 if quick else 3)
    return BenchRow(
        "tracking[walk]", "x real time", seconds / wall, 1.0, "real time", f"{seconds:.0f} s"
    )


def _retarget_row(quick: bool) -> BenchRow:
    path = MOCAP_DIR / CMU_CLIP
    real = path.is_file()
    motion = load_motion(path) if real else generate("walk", duration_s=2.0)
    motion = motion[: 60 if quick else motion.n_frames]
    t0 = time.perf_counter()
    retarget(motion)
    wall = time.perf_counter() - t0
    return BenchRow(
        f"retarget[{path.stem if real else 'walk'}]",
        "frames/s",
        motion.n_frames / wall,
        motion.fps,
        "clip fps",
        f"{motion.n_frames} frames, body fitting included",
    )


def run(quick: bool = False) -> list[BenchRow]:
    """Tracking and retargeting rows; see the module docstring."""
    return [_tracking_row(quick), _retarget_row(quick)]

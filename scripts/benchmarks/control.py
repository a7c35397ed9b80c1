"""Physics control speed next to real time, how long walks stay upright, and IK
retargeting frames/s.

Rows: simulated seconds per wall second following the built-in walk with the plain controller
(``sim.control.controller``: a whole-body QP every 5 simulation steps, 100 Hz; aim at least 10x
real time) and with the search (``sim.control.search``: 48 samples of every 0.2 s window, each
judged 0.2 s later), next to real time (1x); the share of 10 s built-in walks (seeds 0-3)
followed without a fall by the search, next to the plain controller's share (not in
``--quick``); retargeting frames/s (``sim.retarget``: body17 IK with mink, stance feet levelled for
control, as :func:`sim.humanoid.humanoid_for` does for a foreign rig) on a Bandai walk from
the mocap folder (``bench --mocap`` or ``$AVATARSIM_MOCAP``; the built-in walk without one),
next to the clip's own frame rate.
"""

from __future__ import annotations

import time
from pathlib import Path

from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.benchmarks import BenchRow, best_of
from avatarsim.sim.control.controller import control
from avatarsim.sim.control.search import search
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.retarget import retarget

RETARGET_CLIP = "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"


def _speed_rows(quick: bool) -> list[BenchRow]:
    seconds = 1.0 if quick else 2.0  # the plain controller stays upright 2 s (tests)
    walk = generate("walk", duration_s=seconds, fps=30.0)
    h = humanoid_for(walk)
    model = h.control_model()
    repeats = 1 if quick else 3
    plain = best_of(lambda: control(model, h.qpos, walk.fps), repeats)
    searched = best_of(lambda: search(model, h.qpos, walk.fps), 1)
    note = f"{seconds:.0f} s walk"
    return [
        BenchRow("control[walk, plain]", "x real time", seconds / plain, 1.0, "real time", note),
        BenchRow(
            "control[walk, search]", "x real time", seconds / searched, 1.0, "real time", note
        ),
    ]


def _upright_row() -> BenchRow:
    seeds, seconds = range(4), 10.0
    upright = {"plain": 0, "search": 0}
    for seed in seeds:
        walk = generate("walk", duration_s=seconds, fps=30.0, seed=seed)
        h = humanoid_for(walk)
        model = h.control_model()
        upright["plain"] += not control(model, h.qpos, walk.fps).fell
        upright["search"] += not search(model, h.qpos, walk.fps).result.fell
    n = len(seeds)
    return BenchRow(
        "upright[walk 10 s, search]",
        "share of seeds",
        upright["search"] / n,
        upright["plain"] / n,
        "plain controller",
        f"seeds 0-{n - 1}",
    )


def _retarget_row(quick: bool, mocap: Path | None) -> BenchRow:
    path = None if mocap is None else mocap / RETARGET_CLIP
    real = path is not None and path.is_file()
    motion = load_motion(path) if real else generate("walk", duration_s=2.0)
    motion = motion[: 60 if quick else motion.n_frames]
    t0 = time.perf_counter()
    retarget(motion, level_feet=True)
    wall = time.perf_counter() - t0
    return BenchRow(
        f"retarget[{path.stem if real else 'walk'}]",
        "frames/s",
        motion.n_frames / wall,
        motion.fps,
        "clip fps",
        f"{motion.n_frames} frames, body fitting included",
    )


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """Control and retargeting rows; see the module docstring."""
    return [*_speed_rows(quick), *([] if quick else [_upright_row()]), _retarget_row(quick, mocap)]

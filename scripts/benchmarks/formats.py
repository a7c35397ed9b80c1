"""BVH parsing and forward kinematics, next to bvhio (a PyPI BVH library) in the same process.

Rows: BVH parse throughput in MB/s (our ``read_bvh``, which also builds the ``Motion``, vs
``bvhio.readAsBvh``) and forward kinematics in (frames x joints)/s (``Motion.global_positions``
vs bvhio's ``loadPose`` + ``PositionWorld`` per frame). Files: a CMU and a Bandai clip from
the mocap folder (``bench --mocap`` or ``$AVATARSIM_MOCAP``); a generated clip without one.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from avatarsim.avatar_models.formats.bvh import read_bvh, write_bvh
from avatarsim.avatar_models.generator import generate
from avatarsim.scripts.benchmarks import BenchRow, best_of

REAL_CLIPS = ("cmu/125_01.bvh", "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh")


def _generated_clip(folder: Path) -> Path:
    """A built-in walk at 120 fps (the CMU rate), 5 s, as BVH in centimetres."""
    motion = generate("walk", duration_s=5.0, fps=120.0, seed=0)
    return write_bvh(motion, folder / "generated.bvh", unit="cm")


def _bvhio_fk(root, frames: int) -> None:
    """bvhio's forward kinematics: pose each frame, read every joint's world position."""
    joints = [j for j, _, _ in root.layout()]
    for frame in range(frames):
        root.loadPose(frame)
        for joint in joints:
            _ = joint.PositionWorld


def _rows_for(path: Path, label: str, quick: bool) -> list[BenchRow]:
    import bvhio

    megabytes = path.stat().st_size / 1e6
    unit = "cmu" if "cmu" in label else "cm"
    repeat = 2 if quick else 5
    ours = best_of(lambda: read_bvh(path, unit=unit), repeat)
    theirs = best_of(lambda: bvhio.readAsBvh(str(path)), 1 if quick else 2)
    rows = [
        BenchRow(
            f"bvh_parse[{label}]",
            "MB/s",
            megabytes / ours,
            megabytes / theirs,
            "bvhio.readAsBvh",
            f"{megabytes:.2f} MB",
        )
    ]
    motion = read_bvh(path, unit=unit)
    n_joints = sum(1 for s in motion.skeleton.is_site if not s)  # bvhio has no end-site joints
    fk_ours = best_of(lambda: motion.replace().global_positions(), repeat)
    frames = min(motion.n_frames, 30 if quick else 120)
    hierarchy = bvhio.readAsHierarchy(str(path))  # built once, outside the timing
    fk_theirs = best_of(lambda: _bvhio_fk(hierarchy, frames), 1)
    rows.append(
        BenchRow(
            f"fk[{label}]",
            "frames*joints/s",
            motion.n_frames * motion.skeleton.n_joints / fk_ours,
            frames * n_joints / fk_theirs,
            "bvhio loadPose+PositionWorld",
            f"{motion.n_frames} frames x {motion.skeleton.n_joints} joints",
        )
    )
    return rows


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """Parse and FK rows per clip; see the module docstring."""
    if mocap is not None:
        return [
            row for clip in REAL_CLIPS for row in _rows_for(mocap / clip, clip.split("/")[0], quick)
        ]
    with tempfile.TemporaryDirectory() as tmp:
        return _rows_for(_generated_clip(Path(tmp)), "generated", quick)

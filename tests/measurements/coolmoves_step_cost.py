"""What one CoolMoves ``step()`` costs, and whether a change kept its output.

The input is ``avatarsim bench coolmoves``'s (the generator's five Table-1 activities for
four subjects, a held-out subject's boxing through the default ``VRSetup``) and, where the
real mocap is present, a Bandai dataset-2 walk driving a database of three other takes.

    python tests/measurements/coolmoves_step_cost.py outputs OUT.npz
        run and step outputs of ``coolmoves`` and ``coolmoves+arm-ik`` on both inputs
    python tests/measurements/coolmoves_step_cost.py compare BEFORE.npz AFTER.npz
        largest difference of each output, and of step against run
    python tests/measurements/coolmoves_step_cost.py timing [REPEATS]
        thread CPU time of each step: per frame the best of REPEATS passes (what the step
        costs), and every pass (what it costs on this machine now), with the load average

The script uses only the registry and the synthesiser contract, so it runs on another
checkout too: ``PYTHONPATH=/path/to/main python <this file> outputs main.npz``.

Readings of past changes are in the commit log
(``git log -p -- tests/measurements/coolmoves_step_cost.py``).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import avatarsim.avatar_models  # noqa: F401  (the headless GL backend, before anything imports mujoco)
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.coolmoves import build_database
from avatarsim.synthesis.evaluate import PAPER_ACTIVITIES
from avatarsim.synthesis.methods import MethodInputs, build

METHODS = ("coolmoves", "coolmoves+arm-ik")
MOCAP = Path(
    os.environ.get(
        "AVATARSIM_MOCAP", Path(__file__).resolve().parents[2].parent / "shared" / "mocap"
    )
)
"""Real mocap, as the tests find it (``tests/conftest.py``)."""


def bench_input():
    """The bench's database, user height and stream."""
    rng = np.random.default_rng(0)
    subjects = [sample_subject(rng) for _ in range(5)]
    motions = [
        generate(a, s, 8.0, 90.0, seed=10 * i + j)
        for i, s in enumerate(subjects[:4])
        for j, a in enumerate(PAPER_ACTIVITIES)
    ]
    stream = VRSetup().sample(generate("box", subjects[-1], 8.0, 90.0, seed=99))
    return build_database(motions), subjects[-1].height_m, stream


def bandai_input():
    """A dataset-2 walk (6 s) and a database of three other takes, or None without mocap."""
    from avatarsim.avatar_models.library import MotionLibrary

    folder = MOCAP / "bandai" / "dataset-2"
    if not folder.is_dir():
        return None
    clips = MotionLibrary.index(folder).query(activity="walk", style=["exhausted", "youthful"])
    takes = {(c.style, int(c.take)): c.load() for c in clips}
    database = build_database(
        [takes[("exhausted", 2)], takes[("youthful", 2)], takes[("exhausted", 3)]]
    )
    truth = takes[("exhausted", 1)]
    return database, None, VRSetup().sample(truth[: int(6 * truth.fps)], seed=0)


def outputs() -> dict[str, np.ndarray]:
    arrays = {}
    inputs = {"bench": bench_input(), "bandai": bandai_input()}
    for tag, given in inputs.items():
        if given is None:
            print(f"{tag}: no real mocap under {MOCAP}, skipped")
            continue
        database, height, stream = given
        for method in METHODS:
            synth = build(method, MethodInputs(lambda d=database: d, height, database.skeleton))
            motion = synth.run(stream)
            synth.reset()
            steps = [
                synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)
            ]
            arrays[f"{tag}/{method}/run_rot"] = motion.local_rot
            arrays[f"{tag}/{method}/run_root"] = motion.root_pos
            arrays[f"{tag}/{method}/step_rot"] = np.stack([p.local_rot for p in steps])
            arrays[f"{tag}/{method}/step_root"] = np.stack([p.root_pos for p in steps])
    return arrays


def compare(before: Path, after: Path) -> None:
    a, b = np.load(before), np.load(after)
    for key in a.files:
        print(f"{key:36s} max |after - before| {np.max(np.abs(b[key] - a[key])):.3e}")
    for key in (k for k in b.files if "/run_" in k):
        diff = np.max(np.abs(b[key] - b[key.replace("/run_", "/step_")]))
        print(f"{key.replace('/run_', '/step-vs-run_'):36s} max |step - run| {diff:.3e}")


def print_step_timing(label: str, synth, stream, repeats: int) -> None:
    """Thread CPU time of each ``synth.step`` over ``stream``, ``repeats`` passes: per frame
    the best pass, and every pass, as p50 / p99 with the load average."""
    frames = [TrackingFrame.from_stream(stream, i) for i in range(stream.n_samples)]
    cpu = np.empty((repeats, len(frames)))
    for r in range(repeats):
        synth.reset()
        for i, frame in enumerate(frames):
            start = time.thread_time_ns()
            synth.step(frame)
            cpu[r, i] = time.thread_time_ns() - start
    best, every = cpu.min(axis=0) / 1e6, cpu / 1e6
    print(
        f"{label:18s} CPU ms per step, best of {repeats} per frame: "
        f"p50 {np.percentile(best, 50):.3f} p99 {np.percentile(best, 99):.3f}; "
        f"every pass: p50 {np.percentile(every, 50):.3f} p99 {np.percentile(every, 99):.3f}; "
        f"load {os.getloadavg()[0]:.2f}"
    )


def timing(repeats: int) -> None:
    database, height, stream = bench_input()
    for method in METHODS:
        synth = build(method, MethodInputs(lambda: database, height, database.skeleton))
        print_step_timing(method, synth, stream, repeats)


def main(outputs, timing) -> None:
    """The command line of this script and of its siblings (module docstring), on their own
    ``outputs() -> dict`` and ``timing(repeats)``."""
    command = sys.argv[1] if len(sys.argv) > 1 else "timing"
    if command == "outputs":
        np.savez(sys.argv[2], **outputs())
    elif command == "compare":
        compare(Path(sys.argv[2]), Path(sys.argv[3]))
    elif command == "timing":
        timing(int(sys.argv[2]) if len(sys.argv) > 2 else 7)
    else:
        sys.exit(f"unknown command {command!r}: outputs OUT.npz | compare A.npz B.npz | timing [N]")


if __name__ == "__main__":
    main(outputs, timing)

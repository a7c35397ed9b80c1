"""Benchmarks for ``avatarsim bench``: each module exposes ``run(quick=False) -> list[BenchRow]``.

A row compares our implementation with a baseline timed in the same process (machines are
noisy, so ratios are what we report), e.g. BVH parse MB/s next to a PyPI parser.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

# name -> module under scripts.benchmarks; a new benchmark is a new module plus a line here.
BENCHMARKS: dict[str, str] = {
    "formats": "formats",
    "checks": "checks",
    "coolmoves": "coolmoves",
    "avatargo": "avatargo",
    "cameras": "cameras",
    "sensing": "sensing",
    "kinect": "kinect",
    "movebox": "movebox",
    "control": "control",
    "suite": "suite",
    "dataset": "dataset",
    "controllerpose": "controllerpose",
}


@dataclass(frozen=True)
class BenchRow:
    """One measurement: ``value`` in ``unit`` (higher is better unless the unit says s/ms)."""

    name: str
    unit: str
    value: float
    baseline: float | None = None
    baseline_name: str = ""
    note: str = ""

    @property
    def ratio(self) -> float | None:
        if self.baseline is None or self.baseline == 0:
            return None
        return self.value / self.baseline

    def to_json(self) -> dict:
        return {**asdict(self), "ratio": self.ratio}


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    """Best wall time in seconds of ``repeat`` calls (the least-disturbed run)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run_benchmark(name: str, quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    """Rows of benchmark ``name``; ``mocap`` is the real-mocap folder for the benchmarks that
    read real clips (:func:`avatar_models.mocap_dir.mocap_dir`; None: generated motion)."""
    if name not in BENCHMARKS:
        raise KeyError(name)
    module = importlib.import_module(f"avatarsim.scripts.benchmarks.{BENCHMARKS[name]}")
    return module.run(quick=quick, mocap=mocap)

"""MoveBox step latency: the streaming ``step`` that takes in a new 30 Hz Kinect
frame (retargeting, tracking-state rules, smoothing), per sensor, next to the IK baseline's
``step`` on the same VR stream, timed in the same process.

Rows: ms per step that consumes a Kinect frame (median), and the median of the 90 Hz steps in
between (smoothing only); baseline: the IK baseline's median step.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.render_cams.kinect import kinect_skeleton
from avatarsim.render_cams.vr import VRSetup
from avatarsim.scripts.benchmarks import BenchRow
from avatarsim.synthesis.ik_baseline import IKBaseline
from avatarsim.synthesis.movebox import MoveBox
from avatarsim.synthesis.scoring import step_latencies_ms

SENSORS = ("kinect-v2", "azure-kinect")


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    truth = generate("box", duration_s=2.0 if quick else 8.0, fps=90.0, seed=0)
    stream = VRSetup().sample(truth, seed=0)
    baseline = float(
        np.median(step_latencies_ms(IKBaseline(truth.skeleton, standing_height(truth)), stream))
    )
    rows = []
    for sensor in SENSORS:
        # The oracle skeleton (not a sensor): a step's cost does not depend on where the
        # joints came from, and tracking the depth would put rendering into a step bench.
        kinect = kinect_skeleton(truth, sensor, seed=0)
        latencies = step_latencies_ms(MoveBox(kinect, truth.skeleton), stream)
        consumed = np.searchsorted(kinect.timestamps, stream.timestamps, side="right")
        new_frame = np.diff(consumed, prepend=0) > 0
        for label, chosen in (("kinect_frame", new_frame), ("between", ~new_frame)):
            rows.append(
                BenchRow(
                    f"movebox_step_{label}[{sensor}]",
                    "ms",
                    float(np.median(latencies[chosen])),
                    baseline,
                    "ik baseline step",
                    f"{int(chosen.sum())} steps; median",
                )
            )
    return rows

"""What the stages of a scenario run share: inputs, intermediate results, metrics, outputs."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console

from avatarsim.avatar_models.motion import Motion
from avatarsim.render_cams.kinect import KinectSkeletonStream
from avatarsim.render_cams.tracking import TrackingStream
from avatarsim.scripts.results import ThresholdResult
from avatarsim.scripts.scenario import Scenario
from avatarsim.sim.humanoid import Humanoid
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.controllerpose.synthesizer import KeypointRecording


@dataclass
class RunContext:
    """Filled stage by stage; each stage's products are typed fields, named after them.

    Attributes:
        motion: the ground truth (stage ``motion``; ``body`` rescales it to ``[body]``).
        humanoid: its body, built once (stage ``body``) and used by every later stage.
        vr_stream: the simulated VR tracking stream (stage ``devices``; None without
            ``[devices] vr``), the synthesisers' input.
        walk_in: the VR devices' sample while the user stands in a T-pose before the session
            (stage ``devices``, with ``[devices] trackers``; None without), AvatarGo's
            walk-in calibration.
        kinect_stream: the Kinect skeleton stream (stage ``devices``; None without
            ``[devices] kinect``), MoveBox's input.
        fisheye_keypoints: the controller cameras' keypoints (stage ``devices``; None
            without ``[devices] fisheye``), ControllerPose's input.
        synthesised: each method's output on the humanoid, by method name (stage
            ``synthesis``; empty without ``[synthesis]``).
        metrics: thresholded by ``[thresholds]``.
        checks: rows a stage judged itself (e.g. physics checks with their own thresholds).
        info: per-stage summaries written to ``results.json``.
        outputs: written files by key, relative to ``out_dir``.
    """

    scenario: Scenario
    out_dir: Path
    console: Console
    motion: Motion | None = None
    humanoid: Humanoid | None = None
    vr_stream: TrackingStream | None = None
    walk_in: TrackingFrame | None = None
    kinect_stream: KinectSkeletonStream | None = None
    fisheye_keypoints: KeypointRecording | None = None
    synthesised: dict[str, Humanoid] = field(default_factory=dict)
    metrics: dict[str, float] = field(default_factory=dict)
    checks: list[ThresholdResult] = field(default_factory=list)
    info: dict[str, Any] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)

    def output(self, key: str, path: Path) -> Path:
        """Record a written file under ``key`` (relative to the output folder)."""
        self.outputs[key] = str(Path(path).relative_to(self.out_dir))
        return Path(path)

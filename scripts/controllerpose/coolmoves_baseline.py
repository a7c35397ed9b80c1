"""CoolMoves from the VR stream alone, as a baseline of ``eval controllerpose``.

The registry's ``coolmoves`` (CoolMoves §3.1 as the paper describes it: headset and two
controllers, no cameras) with a database of the dataset's *training split* only: the motions
the train samples were recorded from, regenerated from the dataset's plan
(:func:`scripts.dataset.motion_source.window_motion`: the same subjects, activities and
window seeds). Each evaluated recording's VR stream (a sample's ``vr_*``, or a real clip's
as the simulated devices record it) drives it at the user's height; its body17 keypoints
are read at the same camera frames as the examples (the newest 90 Hz tick at or before each
frame, so it never sees a later VR sample than ControllerPose does), then normalised by
:func:`synthesis.controllerpose.evaluate.normalise` like every other row of the table.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import TrackingStream
from avatarsim.scripts.dataset.config import from_dict
from avatarsim.scripts.dataset.manifest import read_manifest
from avatarsim.scripts.dataset.motion_source import window_motion
from avatarsim.scripts.dataset.plan import plan_samples
from avatarsim.synthesis.controllerpose.examples import Examples
from avatarsim.synthesis.coolmoves import Database
from avatarsim.synthesis.methods import METHODS, MethodInputs

METHOD = "coolmoves"


def training_motions(root: Path) -> list[Motion]:
    """The motions of the train split of dataset ``root``, one per planned train window."""
    config = from_dict(read_manifest(root)["config"])
    windows = {s.window.index: s.window for s in plan_samples(config) if s.split == "train"}
    return [window_motion(config, w) for w in windows.values()]


def coolmoves_positions(
    database: Database, streams: dict[int, tuple[TrackingStream, float]], examples: Examples
) -> np.ndarray:
    """World body17 keypoints ``(N, 17, 3)`` of CoolMoves at each of ``examples``, driven by
    ``streams[group]`` (its recording's VR stream and the user's height)."""
    out = np.zeros(examples.positions.shape, dtype=np.float64)
    for group in np.unique(examples.group):
        stream, height = streams[int(group)]
        synth = METHODS[METHOD].build(MethodInputs(lambda: database, height, database.skeleton))
        motion = synth.run(stream)
        rows = np.flatnonzero(examples.group == group)
        since_start = examples.time[rows] - float(stream.timestamps[0])
        tick = np.floor(since_start * motion.fps + 1e-6).astype(int)
        out[rows] = body17_positions(motion[np.clip(tick, 0, motion.n_frames - 1)])
    return out

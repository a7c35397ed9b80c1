"""CoolMoves from the VR stream alone, as a baseline of ``eval controllerpose`` (issue 12).

The registry's ``coolmoves`` (CoolMoves §3.1 as the paper describes it: headset and two
controllers, no cameras) with a database of the dataset's *training split* only: the motions
the train samples were recorded from, regenerated from the dataset's plan
(:func:`scripts.dataset.motion_source.window_motion`: the same subjects, activities and
window seeds). Each evaluated sample's recorded VR stream (``vr_*``) drives it at the user's
height; its body17 keypoints are read at the same camera frames as the examples (the newest
90 Hz tick at or before each frame, so it never sees a later VR sample than ControllerPose
does), then normalised by :func:`synthesis.controllerpose.evaluate.normalise` like every
other row of the table.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatar_models.motion import Motion
from avatar_models.rigs import body17_positions
from render_cams import TrackingStream
from scripts.controllerpose.data import sample_height, split_samples
from scripts.dataset.config import from_dict
from scripts.dataset.manifest import read_manifest
from scripts.dataset.motion_source import window_motion
from scripts.dataset.plan import plan_samples
from synthesis.controllerpose.examples import Examples
from synthesis.coolmoves import Database
from synthesis.methods import METHODS, MethodInputs

METHOD = "coolmoves"


def training_motions(root: Path) -> list[Motion]:
    """The motions of the train split of dataset ``root``, one per planned train window."""
    config = from_dict(read_manifest(root)["config"])
    windows = {s.window.index: s.window for s in plan_samples(config) if s.split == "train"}
    return [window_motion(config, w) for w in windows.values()]


def coolmoves_positions(
    database: Database, root: Path, split: str, examples: Examples
) -> np.ndarray:
    """World body17 keypoints ``(N, 17, 3)`` of CoolMoves at each of ``examples`` (those
    of :func:`scripts.controllerpose.data.load_examples` on the same ``root`` and
    ``split``), driven by its sample's VR stream."""
    out = np.zeros(examples.positions.shape, dtype=np.float64)
    wanted = set(np.unique(examples.group).tolist())
    for group, sample in split_samples(root, split):
        if group not in wanted:
            continue
        meta = sample["json"]
        stream = TrackingStream(
            tuple(meta["channels"]["vr"]["devices"]),
            sample["vr_time"].numpy(),
            sample["vr_pos"].numpy(),
            sample["vr_quat"].numpy(),
            sample["vr_valid"].numpy(),
            meta={"rate_hz": float(meta["channels"]["vr"]["rate_hz"])},
        )
        height = sample_height(sample, sample["body17"].numpy())
        synth = METHODS[METHOD].build(MethodInputs(lambda: database, height, database.skeleton))
        motion = synth.run(stream)
        rows = np.flatnonzero(examples.group == group)
        since_start = examples.time[rows] - float(stream.timestamps[0])
        tick = np.floor(since_start * motion.fps + 1e-6).astype(int)
        out[rows] = body17_positions(motion[np.clip(tick, 0, motion.n_frames - 1)])
    return out

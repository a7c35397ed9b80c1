"""The controller cameras' keypoints of a humanoid's motion, as the synthesiser reads them:
the dataset's projection (:func:`scripts.dataset.channels.fisheye_channel`, the same
keypoints the network was trained on, with its detector noise) on the VR stream's clock
(both start at the motion's first frame)."""

from __future__ import annotations

import numpy as np

from scripts.dataset.channels import fisheye_channel
from sim.humanoid import Humanoid
from synthesis.controllerpose.synthesizer import KeypointRecording


def keypoint_recording(humanoid: Humanoid, seed: int) -> KeypointRecording:
    """The four controller cameras' body17 keypoints of ``humanoid``'s motion as the 2D
    detector reports them; ``seed`` drives its errors (misses, swaps, pixel noise)."""
    arrays, meta = fisheye_channel(humanoid, seed)
    n_frames = arrays["fisheye_uv"].shape[0]
    return KeypointRecording(
        np.arange(n_frames) / float(meta["rate_hz"]),
        arrays["fisheye_uv"].astype(np.float64),
        arrays["fisheye_conf"].astype(np.float64),
    )

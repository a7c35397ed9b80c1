"""The four 2D poses of a humanoid's motion (§4.3: each controller's composite and
torso-normal view as the detector reports them), as the synthesiser reads them: the
dataset's (:func:`scripts.dataset.channels.fisheye_channel`, the same keypoints the network
was trained on, with its detector noise) on the VR stream's clock (both start at the
motion's first frame)."""

from __future__ import annotations

import numpy as np

from avatarsim.scripts.dataset.channels import fisheye_channel
from avatarsim.sim.humanoid import Humanoid
from avatarsim.synthesis.controllerpose.synthesizer import KeypointRecording


def keypoint_recording(humanoid: Humanoid, seed: int) -> KeypointRecording:
    """The four 2D body17 poses of ``humanoid``'s motion (left composite, left torso view,
    right composite, right torso view) as the detector reports them; ``seed`` drives its
    errors (misses, swaps, pixel noise)."""
    arrays, meta = fisheye_channel(humanoid, seed)
    n_frames = arrays["fisheye_view_uv"].shape[0]
    return KeypointRecording(
        np.arange(n_frames) / float(meta["rate_hz"]),
        arrays["fisheye_view_uv"].astype(np.float64),
        arrays["fisheye_view_conf"].astype(np.float64),
    )

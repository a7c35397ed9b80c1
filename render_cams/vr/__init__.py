"""Simulated VR tracking: headset, hand controllers and Vive trackers on a moving skeleton.

One concept per module: :mod:`.attachments` (rigid device-on-joint poses and per-user
offsets), :mod:`.placements` (where each device sits), :mod:`.noise` (jitter, latency, drift,
timestamp jitter), :mod:`.dropouts` (tracking loss), :mod:`.faults` (contract-breaking faults
for robustness tests) and :mod:`.setup` (the ``VRSetup`` device that ties them together).
"""

from avatarsim.render_cams.vr.attachments import Attachment, OffsetSpread, attachment_poses
from avatarsim.render_cams.vr.dropouts import Dropouts, Occlusion
from avatarsim.render_cams.vr.faults import NaNSamples, OutOfOrder
from avatarsim.render_cams.vr.noise import (
    REALISTIC_NOISE,
    Drift,
    Latency,
    NoiseModel,
    PositionJitter,
    RotationJitter,
    TimestampJitter,
)
from avatarsim.render_cams.vr.placements import (
    FULL_BODY,
    HEADSET_AND_CONTROLLERS,
    nominal_attachment,
)
from avatarsim.render_cams.vr.setup import VRSetup

__all__ = [
    "FULL_BODY",
    "REALISTIC_NOISE",
    "HEADSET_AND_CONTROLLERS",
    "Attachment",
    "Drift",
    "Dropouts",
    "Latency",
    "NaNSamples",
    "NoiseModel",
    "Occlusion",
    "OffsetSpread",
    "OutOfOrder",
    "PositionJitter",
    "RotationJitter",
    "TimestampJitter",
    "VRSetup",
    "attachment_poses",
    "nominal_attachment",
]

"""``VRSetup``: a VR system (headset, controllers, optional Vive trackers) as one ``Device``.

``VRSetup().sample(motion, seed)`` places the devices on the motion's skeleton (any rig with a
``body17`` map), samples them on one clock at ``rate_hz`` (90 Hz, the rate of the HTC Vive
that CoolMoves registers, coolmoves.txt §3.1) and applies the noise models in order. Each
user gets offsets: the nominal placements, overridden per device by ``offsets``, then
perturbed by ``offset_spread`` when one is given. Everything random comes from one seed,
split with ``numpy.random.SeedSequence`` so that adding a noise model leaves the draws of the
others unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.render_cams.device import DeviceError, check_rate, motion_at_rate, resolve_seed
from avatarsim.render_cams.tracking import TrackingStream, UnknownDeviceError
from avatarsim.render_cams.vr.attachments import Attachment, OffsetSpread, attachment_poses
from avatarsim.render_cams.vr.noise import NoiseModel, describe
from avatarsim.render_cams.vr.placements import (
    FULL_BODY,
    HEADSET_AND_CONTROLLERS,
    nominal_attachment,
)


@dataclass(frozen=True)
class VRSetup:
    """The tracked devices of one VR system and how they are sampled.

    Attributes:
        devices: names from :data:`~render_cams.vr.placements.FULL_BODY`; the default is
            CoolMoves' headset and two controllers.
        rate_hz: sampling rate of the shared clock.
        noise: noise models applied in this order (see :mod:`render_cams.vr.noise`).
        offsets: explicit attachments for some devices, replacing the nominal ones.
        offset_spread: per-user random offsets around the attachments (None: exact).
    """

    devices: tuple[str, ...] = HEADSET_AND_CONTROLLERS
    rate_hz: float = 90.0
    noise: tuple[NoiseModel, ...] = ()
    offsets: Mapping[str, Attachment] = field(default_factory=dict)
    offset_spread: OffsetSpread | None = None
    name: str = "vr"

    def __post_init__(self) -> None:
        devices = (self.devices,) if isinstance(self.devices, str) else tuple(self.devices)
        for device in (*devices, *self.offsets):
            if device not in FULL_BODY:
                raise UnknownDeviceError(device, FULL_BODY)
        if len(set(devices)) != len(devices) or not devices:
            raise DeviceError(f"devices must be distinct and at least one, got {devices}")
        object.__setattr__(self, "devices", devices)
        object.__setattr__(self, "rate_hz", check_rate(self.rate_hz))
        object.__setattr__(self, "noise", tuple(self.noise))
        object.__setattr__(self, "offsets", dict(self.offsets))

    def attachments(self, motion: Motion, rng: np.random.Generator) -> list[Attachment]:
        """This user's attachment of each device, in ``devices`` order."""
        out = []
        for device in self.devices:
            attachment = self.offsets.get(device) or nominal_attachment(device, motion.skeleton)
            if self.offset_spread is not None:
                attachment = self.offset_spread.perturb(attachment, rng)
            out.append(attachment)
        return out

    def sample(self, motion: Motion, seed: int | np.random.Generator = 0) -> TrackingStream:
        """The tracking stream of ``motion`` as this setup reports it."""
        seed = resolve_seed(seed)
        offsets_seq, *noise_seqs = np.random.SeedSequence(seed).spawn(1 + len(self.noise))
        attachments = self.attachments(motion, np.random.default_rng(offsets_seq))
        sampled = motion_at_rate(motion, self.rate_hz)
        positions, quaternions = attachment_poses(sampled, attachments)
        stream = TrackingStream(
            device_names=self.devices,
            timestamps=np.arange(sampled.n_frames) / self.rate_hz,
            positions=positions,
            quaternions=quaternions,
            valid=np.ones(positions.shape[:2], bool),
            meta={
                "device": self.name,
                "seed": seed,
                "rate_hz": self.rate_hz,
                "offsets": {d: a.as_dict() for d, a in zip(self.devices, attachments, strict=True)},
                "noise": [describe(model) for model in self.noise],
                "motion": {
                    "skeleton": motion.skeleton.name,
                    "fps": motion.fps,
                    "frames": motion.n_frames,
                },
            },
        )
        for model, seq in zip(self.noise, noise_seqs, strict=True):
            stream = model.apply(stream, np.random.default_rng(seq))
        return stream

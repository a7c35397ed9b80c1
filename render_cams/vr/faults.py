"""Contract-breaking faults for robustness tests: NaN marked valid, out-of-order packets.

Real drivers occasionally deliver garbage: a NaN pose still flagged as tracked, packets that
arrive late or twice. These models produce such streams on purpose; they fail
:meth:`TrackingStream.validate` and a consumer is expected to cope, e.g. by
:meth:`TrackingStream.repaired`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.tracking import TrackingStream
from avatarsim.render_cams.vr.noise import target_mask


def _check_fraction(model: object, *names: str) -> None:
    for name in names:
        value = getattr(model, name)
        if not (isinstance(value, int | float) and 0.0 <= value <= 1.0):
            raise DeviceError(f"{type(model).__name__}.{name} must be in [0, 1], got {value!r}")


@dataclass(frozen=True)
class NaNSamples:
    """A ``fraction`` of each targeted device's samples become NaN yet stay marked valid."""

    fraction: float = 0.01
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        _check_fraction(self, "fraction")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        hit = rng.random(stream.valid.shape) < self.fraction
        hit[:, ~target_mask(stream, self.devices)] = False
        return stream.replace(
            positions=np.where(hit[..., None], np.nan, stream.positions),
            quaternions=np.where(hit[..., None], np.nan, stream.quaternions),
        )


@dataclass(frozen=True)
class OutOfOrder:
    """Packet faults on whole samples: a ``swap_fraction`` of samples trade places with their
    successor (timestamps and poses move together, so stamps run backwards; a swap is
    skipped when the previous sample already swapped), and a
    ``duplicate_fraction`` arrive twice (an identical sample right after the first)."""

    swap_fraction: float = 0.01
    duplicate_fraction: float = 0.0
    devices: tuple[str, ...] | None = None  # packets carry every device: only None is meaningful

    def __post_init__(self) -> None:
        _check_fraction(self, "swap_fraction", "duplicate_fraction")
        if self.devices is not None:
            raise DeviceError("OutOfOrder reorders whole samples; leave devices=None")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        n = stream.n_samples
        order = np.arange(n)
        picked = rng.random(max(n - 1, 0)) < self.swap_fraction
        # Swaps with the next sample must not overlap, so drop any whose predecessor was picked.
        picked[1:] &= ~picked[:-1]
        swap = np.flatnonzero(picked)
        order[swap], order[swap + 1] = swap + 1, swap
        copies = 1 + (rng.random(n) < self.duplicate_fraction)
        return stream[np.repeat(order, copies[order])]

"""Tracking loss: samples a device did not deliver, marked invalid and NaN-filled.

Outside-in tracking loses a device when its sensors leave the base stations' view, e.g. a
controller hidden behind the body for a second. :class:`Dropouts` draws such bursts at random,
:class:`Occlusion` scripts one at a known time (for fault tests).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.tracking import TrackingStream
from avatarsim.render_cams.vr.noise import check_non_negative, target_mask


def invalidate(stream: TrackingStream, lost: np.ndarray) -> TrackingStream:
    """``stream`` with the samples where ``lost (T, D)`` is True marked invalid, NaN-filled."""
    valid = stream.valid & ~lost
    return stream.replace(
        positions=np.where(valid[..., None], stream.positions, np.nan),
        quaternions=np.where(valid[..., None], stream.quaternions, np.nan),
        valid=valid,
    )


@dataclass(frozen=True)
class Dropouts:
    """Bursts of tracking loss, each ``duration_s`` long, starting as a Poisson process of
    ``bursts_per_s`` per device. A burst starting at ``s`` loses the samples with timestamps in
    ``[s, s + duration_s)``; overlapping bursts merge. The expected lost fraction is
    ``1 - exp(-bursts_per_s * duration_s)`` (coverage of a Poisson process of intervals).
    """

    bursts_per_s: float = 0.05
    duration_s: float = 0.5
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        check_non_negative(self, "bursts_per_s", "duration_s")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        ts = stream.timestamps
        lost = np.zeros(stream.valid.shape, bool)
        if ts.size == 0:
            return stream
        # Bursts may start up to one duration before the first sample, so that the stream's
        # start is covered as often as any other instant.
        t0, t1 = ts.min() - self.duration_s, ts.max()
        counts = rng.poisson(self.bursts_per_s * (t1 - t0), stream.n_devices)
        starts = rng.uniform(t0, t1, counts.sum())
        owner = np.repeat(np.arange(stream.n_devices), counts)
        # Samples covered by any burst: +1 at each burst start, -1 at its end, cumulated.
        edges = np.zeros((ts.size + 1, stream.n_devices), np.int64)
        order = np.argsort(ts, kind="stable")
        first = np.searchsorted(ts[order], starts, side="left")
        last = np.searchsorted(ts[order], starts + self.duration_s, side="left")
        np.add.at(edges, (first, owner), 1)
        np.add.at(edges, (last, owner), -1)
        lost[order] = np.cumsum(edges, axis=0)[:-1] > 0
        lost[:, ~target_mask(stream, self.devices)] = False
        return invalidate(stream, lost)


@dataclass(frozen=True)
class Occlusion:
    """``device`` loses tracking for ``duration_s`` from ``start_s`` (timestamps in
    ``[start_s, start_s + duration_s)``)."""

    device: str
    start_s: float
    duration_s: float = 1.0

    def __post_init__(self) -> None:
        check_non_negative(self, "duration_s")
        if not np.isfinite(self.start_s):
            raise DeviceError(f"Occlusion.start_s must be finite, got {self.start_s!r}")

    @property
    def devices(self) -> tuple[str, ...]:
        return (self.device,)

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        ts = stream.timestamps[:, None]
        hidden = (ts >= self.start_s) & (ts < self.start_s + self.duration_s)
        return invalidate(stream, hidden & target_mask(stream, self.devices)[None, :])

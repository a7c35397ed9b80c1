"""``Synthesizer``: the small protocol every full-body synthesis method follows.

A synthesiser turns tracking samples into full-body poses on its own rig. It works both
streaming, one 90 Hz sample at a time (``reset()`` then ``step(frame) -> Pose``), and in batch
(``run(stream) -> Motion``). Batch output has one frame per tick of a regular clock at the
stream's rate, so that it lines up frame by frame with the ground truth the stream was
sampled from; ticks the stream did not deliver are stepped as invalid frames.

NaN never leaves a synthesiser: invalid or non-finite samples are skipped, and a method holds
or decays its output through them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from avatar_models import AvatarsimError, Motion, Skeleton
from render_cams import TrackingStream

DEFAULT_RATE_HZ = 90.0


class SynthesisError(AvatarsimError, ValueError):
    """A synthesiser cannot work with its input (missing devices, empty database...)."""


@dataclass(frozen=True, eq=False)
class TrackingFrame:
    """One tracking sample of ``D`` devices.

    Attributes:
        timestamp: seconds.
        device_names: ``D`` names (as in :class:`~render_cams.TrackingStream`).
        positions: ``(D, 3)`` metres, world frame.
        quaternions: ``(D, 4)`` wxyz.
        valid: ``(D,)`` bool; a device is usable only where it is True *and* finite.
    """

    timestamp: float
    device_names: tuple[str, ...]
    positions: np.ndarray
    quaternions: np.ndarray
    valid: np.ndarray

    @classmethod
    def from_stream(cls, stream: TrackingStream, index: int) -> TrackingFrame:
        return cls(
            float(stream.timestamps[index]),
            stream.device_names,
            stream.positions[index],
            stream.quaternions[index],
            stream.valid[index],
        )

    def usable(self) -> np.ndarray:
        """``(D,)`` bool: marked valid and holding a finite pose."""
        finite = np.isfinite(self.positions).all(-1) & np.isfinite(self.quaternions).all(-1)
        return np.asarray(self.valid, bool) & finite


@dataclass(frozen=True, eq=False)
class Pose:
    """One full-body pose: ``root_pos (3,)`` world metres and ``local_rot (J, 4)`` wxyz."""

    root_pos: np.ndarray
    local_rot: np.ndarray


def usable_mask(stream: TrackingStream) -> np.ndarray:
    """``(T, D)`` bool: samples marked valid and holding a finite pose."""
    finite = np.isfinite(stream.positions).all(-1) & np.isfinite(stream.quaternions).all(-1)
    return stream.valid & finite


def max_clock_span_s(timestamps: np.ndarray) -> float:
    """The longest time ``on_clock`` accepts for sorted, distinct ``timestamps (T,)``.

    The samples account for ``T`` median periods of their own clock; a stream may miss up
    to as much again (tracking pauses) plus one second. Beyond that the empty ticks
    outnumber the samples and the stream's clock is broken, not paused.
    """
    steps = np.diff(timestamps)
    period = float(np.median(steps)) if steps.size else 0.0
    return 2.0 * timestamps.size * period + 1.0


def on_clock(stream: TrackingStream, rate_hz: float | None = None) -> TrackingStream:
    """``stream`` repaired and placed on a regular clock ``t0 + k / rate_hz``.

    Each sample goes to the nearest tick (timestamp jitter is below half a period); ticks
    that received no sample are invalid (NaN), and of two samples on one tick the later
    one wins. Out-of-order, duplicate, NaN and glitched samples are handled by
    :meth:`TrackingStream.repaired` first.

    Raises:
        SynthesisError: no sample has a finite timestamp, or the samples span more than
            :func:`max_clock_span_s` (a clock jump that would make ``run`` step mostly
            empty ticks for as long as the jump, e.g. a day of them).
    """
    rate = float(rate_hz or stream.rate_hz or DEFAULT_RATE_HZ)
    clean = stream.repaired()
    if clean.n_samples == 0:
        raise SynthesisError("the tracking stream has no sample with a finite timestamp")
    t0 = float(clean.timestamps[0])
    span = float(clean.timestamps[-1]) - t0
    if span > max_clock_span_s(clean.timestamps):
        raise SynthesisError(
            f"the tracking stream's {clean.n_samples} samples span {span:.6g} s, more than "
            f"{max_clock_span_s(clean.timestamps):.6g} s (twice their own duration + 1 s); "
            "its clock jumps (e.g. a reset or a garbage timestamp run): split it at the jump"
        )
    ticks = np.rint((clean.timestamps - t0) * rate).astype(np.int64)
    n = int(ticks[-1]) + 1
    positions = np.full((n, clean.n_devices, 3), np.nan)
    quaternions = np.full((n, clean.n_devices, 4), np.nan)
    valid = np.zeros((n, clean.n_devices), bool)
    positions[ticks] = clean.positions
    quaternions[ticks] = clean.quaternions
    valid[ticks] = clean.valid
    return clean.replace(
        timestamps=t0 + np.arange(n) / rate,
        positions=positions,
        quaternions=quaternions,
        valid=valid,
        meta={**clean.meta, "rate_hz": rate},
    )


class Synthesizer(ABC):
    """Base of every synthesis method: a rig, streaming ``step`` and batch ``run``."""

    name: str = "synthesizer"

    @property
    @abstractmethod
    def skeleton(self) -> Skeleton:
        """The rig the output poses are on."""

    @abstractmethod
    def reset(self) -> None:
        """Forget all state (start of a new session)."""

    @abstractmethod
    def step(self, frame: TrackingFrame) -> Pose:
        """The pose for one new tracking sample; always finite."""

    def run(self, stream: TrackingStream) -> Motion:
        """The motion for a whole stream: :func:`on_clock`, then ``step`` on every tick.

        Methods with a vectorised batch path override this and must give the same result.
        """
        clocked = on_clock(stream)
        self.reset()
        poses = [self.step(TrackingFrame.from_stream(clocked, i)) for i in range(clocked.n_samples)]
        return Motion(
            self.skeleton,
            float(clocked.meta["rate_hz"]),
            np.stack([p.root_pos for p in poses]),
            np.stack([p.local_rot for p in poses]),
            meta={"method": self.name, "stream": clocked.meta},
        )

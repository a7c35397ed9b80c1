"""``Synthesizer``: the contract every full-body synthesis method implements.

A synthesiser turns tracking samples into full-body poses on its own rig. It works both
streaming, one 90 Hz sample at a time (``reset()`` then ``step(frame) -> Pose``), and in batch
(``run(stream) -> Motion``), and both are the same code: a method writes its logic once, as a
core over a batch of consecutive frames that carries its state from one call to the next
(:meth:`Synthesizer.advance`). ``step`` calls that core with a batch of one frame, ``run``
with every tick of the stream at once; so a method cannot behave differently in the two
modes, and a batch method gets streaming for free.

What a method provides (see :class:`Synthesizer`):

- ``name`` (what results and reports call it) and ``devices`` (the tracked devices it needs,
  as named in :class:`~render_cams.TrackingStream`);
- ``skeleton``: the rig its poses are on (``J`` joints);
- ``reset_state()``: forget everything learnt from earlier frames (start of a session);
- ``advance(frames: FrameBatch) -> Poses``: the poses of ``B`` new consecutive frames, given
  the state the previous call left, and that state advanced past them. Frames arrive in time
  order (``step`` drops late and repeated ones before they reach it); any device sample may be
  invalid or non-finite (:meth:`FrameBatch.usable`).

Batch output has one frame per tick of a regular clock at the stream's rate
(:func:`on_clock`), so that it lines up frame by frame with the ground truth the stream was
sampled from; ticks the stream did not deliver are advanced as invalid frames.

NaN never leaves a synthesiser: invalid or non-finite samples are skipped, and a method holds
or decays its output through them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import AvatarsimError, Motion, Skeleton, quat
from avatarsim.render_cams import TrackingStream

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


@dataclass(frozen=True, eq=False)
class Pose:
    """One full-body pose: ``root_pos (3,)`` world metres and ``local_rot (J, 4)`` wxyz."""

    root_pos: np.ndarray
    local_rot: np.ndarray


@dataclass(frozen=True, eq=False)
class FrameBatch:
    """``B`` consecutive tracking samples of ``D`` devices: the input of
    :meth:`Synthesizer.advance`. Views of the caller's arrays, never copied (``step`` builds
    one per 90 Hz sample).

    Attributes:
        timestamps: ``(B,)`` seconds, increasing.
        device_names: ``D`` names (as in :class:`~render_cams.TrackingStream`).
        positions: ``(B, D, 3)`` metres, world frame.
        quaternions: ``(B, D, 4)`` wxyz.
        valid: ``(B, D)`` bool; a sample is usable only where it is True *and* finite.
    """

    timestamps: np.ndarray
    device_names: tuple[str, ...]
    positions: np.ndarray
    quaternions: np.ndarray
    valid: np.ndarray

    @classmethod
    def of_frame(cls, frame: TrackingFrame) -> FrameBatch:
        """A batch of one."""
        return cls(
            np.array([frame.timestamp]),
            frame.device_names,
            np.asarray(frame.positions)[None],
            np.asarray(frame.quaternions)[None],
            np.asarray(frame.valid)[None],
        )

    @classmethod
    def of_stream(cls, stream: TrackingStream) -> FrameBatch:
        return cls(
            stream.timestamps,
            stream.device_names,
            stream.positions,
            stream.quaternions,
            stream.valid,
        )

    @property
    def size(self) -> int:
        """``B``."""
        return self.timestamps.shape[0]

    def usable(self) -> np.ndarray:
        """``(B, D)`` bool: marked valid and holding a finite pose."""
        finite = np.isfinite(self.positions).all(-1) & np.isfinite(self.quaternions).all(-1)
        return np.asarray(self.valid, bool) & finite


@dataclass(frozen=True, eq=False)
class Poses:
    """``B`` full-body poses: ``root_pos (B, 3)`` world metres, ``local_rot (B, J, 4)`` wxyz."""

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
    """Base of every synthesis method: a rig, a batch core, streaming ``step`` and ``run``.

    Subclasses implement :attr:`skeleton`, :meth:`reset_state` and :meth:`advance`, and set
    :attr:`name` and :attr:`devices`; they call :meth:`reset` at the end of ``__init__``.
    They do not override ``step`` or ``run`` (a method may wrap ``run`` in a context, e.g.
    a thread limit, and return ``super().run(stream)``).
    """

    name: str = "synthesizer"
    devices: tuple[str, ...] = ()
    """The tracked devices the method reads (names as in :class:`~render_cams.TrackingStream`)."""

    @property
    @abstractmethod
    def skeleton(self) -> Skeleton:
        """The rig the output poses are on (``J`` joints)."""

    @abstractmethod
    def reset_state(self) -> None:
        """Forget the method's state: the next :meth:`advance` starts a new session."""

    @abstractmethod
    def advance(self, frames: FrameBatch) -> Poses:
        """The poses of ``B = frames.size`` new frames (in time order), each always finite;
        the method's state advances past them, so that two calls on consecutive halves of a
        batch give what one call on the whole batch gives."""

    def settings(self) -> dict:
        """What distinguishes this instance in the output's ``meta`` (e.g. its options)."""
        return {}

    def device_index(self, frames: FrameBatch) -> np.ndarray:
        """Indices ``(len(devices),)`` of :attr:`devices` along the frames' ``D`` axis
        (cached per device list: ``step`` asks once per sample).

        Raises:
            SynthesisError: a device the method needs is not in the frames.
        """
        names = frames.device_names
        cached = self._device_index
        if cached is None or cached[0] != names:
            missing = [d for d in self.devices if d not in names]
            if missing:
                raise SynthesisError(f"{self.name} needs devices {missing}; the stream has {names}")
            cached = (names, np.array([names.index(d) for d in self.devices]))
            self._device_index = cached
        return cached[1]

    def reset(self) -> None:
        """Forget all state (start of a new session)."""
        self._last_time: float | None = None
        self._last_pose: Pose | None = None
        self._device_index: tuple[tuple[str, ...], np.ndarray] | None = None
        self.reset_state()

    def step(self, frame: TrackingFrame) -> Pose:
        """The pose after one new tracking sample: :meth:`advance` on a batch of one.

        A sample not later than the last one (late, repeated or with a NaN timestamp after a
        finite one) is already past: it returns the last pose and leaves the state alone.
        """
        if self._last_time is not None and not frame.timestamp > self._last_time:
            return self._last_pose
        poses = self.advance(FrameBatch.of_frame(frame))
        if np.isfinite(frame.timestamp):
            self._last_time = float(frame.timestamp)
        rot = poses.local_rot[0]
        # Unit length as Motion makes run's output, so that step is bit-identical to run.
        # (np.linalg.norm's sum, without its Python wrapper and its length-4 reduction.)
        self._last_pose = Pose(poses.root_pos[0], rot / np.sqrt(quat.dot(rot, rot))[..., None])
        return self._last_pose

    def run(self, stream: TrackingStream) -> Motion:
        """The motion for a whole stream: :func:`on_clock`, :meth:`reset`, then
        :meth:`advance` on every tick at once (the state is left as ``step`` would leave it)."""
        clocked = on_clock(stream)
        self.reset()
        poses = self.advance(FrameBatch.of_stream(clocked))
        motion = Motion(
            self.skeleton,
            float(clocked.meta["rate_hz"]),
            poses.root_pos,
            poses.local_rot,
            meta={"method": self.name, **self.settings(), "stream": clocked.meta},
        )
        self._last_time = float(clocked.timestamps[-1])
        self._last_pose = Pose(motion.root_pos[-1], motion.local_rot[-1])
        return motion

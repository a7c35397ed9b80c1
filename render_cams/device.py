"""``Device``: the small protocol every simulated device follows, plus its shared helpers.

A device is constructed from its options and turns a ground-truth :class:`~avatar_models.Motion`
into what the hardware would report: ``device.sample(motion, seed) -> recording``. It has a
``name`` and a sampling rate ``rate_hz`` (90 Hz for VR tracking, 30 Hz for Kinect and the
controller cameras). Randomness comes from one seed or ``numpy.random.Generator`` per call;
the seed actually used is recorded in the output. The devices, one module each:

- :class:`render_cams.vr.setup.VRSetup` -> :class:`~render_cams.tracking.TrackingStream`
  (``(T, D, 3)`` positions, ``(T, D, 4)`` quaternions of ``D`` trackers);
- :class:`render_cams.kinect.device.Kinect` -> :class:`~render_cams.kinect.device.KinectRecording`
  (the ``(T, J)`` skeleton stream, ``T`` depth and body-index frames of ``(H, W)``, rendered
  as they are read so that long takes stream);
- :class:`render_cams.fisheye.device.FisheyeRig` ->
  :class:`~render_cams.fisheye.device.FisheyeRecording` (``(C, T, H, W, 3)`` images,
  ``(C, T, H, W)`` range, ``C * T`` keypoint records).

Devices that see the body's surface (the cameras) also take ``body=``, the humanoid built once
for the motion, so that nothing rebuilds it; the trackers follow joints and need none.
Each camera's ``sequence`` module writes a recording to a folder.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from avatarsim.avatar_models import AvatarsimError, Motion


class DeviceError(AvatarsimError, ValueError):
    """A device or noise model configured with impossible values (negative rate, sigma...)."""


@runtime_checkable
class Device(Protocol):
    """What a simulated device offers: a name, a rate and ``sample`` (cameras add ``body=``)."""

    name: str
    rate_hz: float

    def sample(self, motion: Motion, seed: int | np.random.Generator = 0) -> Any:
        """The device's recording of ``motion``; same motion + seed => same bytes."""
        ...


def check_rate(rate_hz: float) -> float:
    """``rate_hz`` as a float; raises :class:`DeviceError` unless it is finite and positive."""
    try:
        rate = float(rate_hz)
    except (TypeError, ValueError):
        raise DeviceError(f"sampling rate must be a number in Hz, got {rate_hz!r}") from None
    if not (np.isfinite(rate) and rate > 0):
        raise DeviceError(f"sampling rate must be positive (e.g. 90 Hz), got {rate_hz!r}")
    return rate


def resolve_seed(seed: int | np.random.Generator) -> int:
    """A plain integer seed: ``seed`` itself, or one drawn from a given generator.

    Drawing an integer from a generator (rather than using it directly) lets every output
    record a seed that reproduces it exactly.
    """
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(0, 2**63 - 1))
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise DeviceError(f"seed must be a non-negative integer or a Generator, got {seed!r}")
    return int(seed)


def sample_times(motion: Motion, rate_hz: float) -> np.ndarray:
    """``(N,)`` sample instants ``k / rate_hz`` covering the motion's duration.

    As :meth:`Motion.resample`, the duration is kept and rounded down: a clip of ``T`` frames
    at ``fps`` gives ``floor((T - 1) / fps * rate_hz) + 1`` samples (3(T - 1) + 1 for 30 -> 90).
    """
    rate = check_rate(rate_hz)
    n = int(np.floor(motion.duration_s * rate + 1e-9)) + 1
    return np.arange(n) / rate


def motion_at_rate(motion: Motion, rate_hz: float) -> Motion:
    """``motion`` sampled at ``rate_hz`` (unchanged when it is already at that rate)."""
    rate = check_rate(rate_hz)
    if abs(motion.fps - rate) < 1e-9:
        return motion  # skip slerp so that samples equal the source frames bit for bit
    return motion.sample(sample_times(motion, rate)).replace(fps=rate)

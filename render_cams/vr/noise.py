"""Sensor noise on tracking streams: jitter, latency, drift and timestamp jitter.

Every model is a small frozen dataclass with ``apply(stream, rng) -> stream``; models compose
by applying them in order (:class:`~render_cams.vr.setup.VRSetup` does that, giving each its
own generator). ``devices`` restricts a model to some devices (None: all). Defaults describe an
outside-in Lighthouse system (HTC Vive); sources are named where a number comes from one:

- Kreylos, "Lighthouse tracking examined" (doc-ok.org/?p=1478, 2016) measured the jitter of a
  static Vive headset at well under a millimetre with both base stations in view, and Valve's
  A. Yates gave ~65 microradian 1-sigma angular repeatability, "better than 300 micron at
  5 metres". Hence ``PositionJitter`` defaults to 0.5 mm per axis.
- Bauer et al., "Accuracy Investigation of the Pose Determination of a VR System", Sensors
  21(5):1622, 2021: reproducibility of a few millimetres, systematic errors of centimetres,
  which the slow :class:`Drift` stands in for.
Other defaults (0.1 degree rotational jitter, latency, drift rate) are assumptions.

Order matters: apply :class:`Latency` first (it shifts by whole sample periods), then drift and
jitter, then dropouts, timestamp jitter and faults.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.tracking import TrackingStream


@runtime_checkable
class NoiseModel(Protocol):
    """A stream-to-stream corruption, seeded by the generator it is given."""

    devices: tuple[str, ...] | None

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream: ...


def describe(model: NoiseModel) -> dict:
    """JSON-ready record of a model and its settings (for stream metadata)."""
    return {"type": type(model).__name__, **asdict(model)}  # type: ignore[call-overload]


def target_mask(stream: TrackingStream, devices: tuple[str, ...] | None) -> np.ndarray:
    """``(D,)`` True for the devices a model acts on (all when ``devices`` is None)."""
    mask = np.zeros(stream.n_devices, bool)
    if devices is None:
        mask[:] = True
    else:
        mask[[stream.device(name) for name in devices]] = True
    return mask


def check_non_negative(model: object, *names: str) -> None:
    """Raise :class:`DeviceError` unless each named setting is finite and >= 0."""
    for name in names:
        value = getattr(model, name)
        if not (isinstance(value, int | float) and np.isfinite(value) and value >= 0):
            raise DeviceError(f"{type(model).__name__}.{name} must be >= 0, got {value!r}")


def nominal_rate(stream: TrackingStream, model: object) -> float:
    """The stream's recorded rate, needed by models that work in sample periods."""
    rate = stream.rate_hz
    if rate is None:
        raise DeviceError(f"{type(model).__name__} needs meta['rate_hz'] on the stream")
    return rate


@dataclass(frozen=True)
class PositionJitter:
    """White Gaussian noise on positions, ``sigma_m`` per axis."""

    sigma_m: float = 0.0005
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        check_non_negative(self, "sigma_m")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        noise = rng.normal(0.0, self.sigma_m, stream.positions.shape)
        noise[:, ~target_mask(stream, self.devices)] = 0.0
        return stream.replace(positions=stream.positions + noise)


@dataclass(frozen=True)
class RotationJitter:
    """White Gaussian rotation noise: a rotation vector with ``sigma_rad`` per axis, applied
    in the device frame (``q * exp(noise)``)."""

    sigma_rad: float = float(np.radians(0.1))
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        check_non_negative(self, "sigma_rad")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        rotvec = rng.normal(0.0, self.sigma_rad, stream.positions.shape)
        rotvec[:, ~target_mask(stream, self.devices)] = 0.0
        noise = quat.from_scipy(Rotation.from_rotvec(rotvec.reshape(-1, 3)), rotvec.shape[:2])
        return stream.replace(quaternions=quat.mul(stream.quaternions, noise))


@dataclass(frozen=True)
class Latency:
    """A fixed delay: the pose reported at sample time ``t`` is the pose at ``t - seconds``.

    Works in sample periods of the nominal rate; a delay of a whole number of periods is an
    exact shift, others interpolate linearly between the two neighbouring samples (positions)
    and by normalised lerp (quaternions; adjacent samples 11 ms apart differ by a few degrees
    at most, where nlerp and slerp agree to far below the jitter). Before the first sample the
    first pose is reported.
    """

    seconds: float = 0.0
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        check_non_negative(self, "seconds")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        shift = self.seconds * nominal_rate(stream, self)
        if abs(shift - round(shift)) < 1e-9:
            shift = float(round(shift))  # exact shifts stay exact despite float seconds
        n = stream.n_samples
        src = np.clip(np.arange(n) - shift, 0.0, n - 1)
        i0 = np.floor(src).astype(np.int64)
        i1 = np.minimum(i0 + 1, n - 1)
        frac = (src - i0)[:, None, None]
        on_sample = frac == 0.0
        pos0, pos1 = stream.positions[i0], stream.positions[i1]
        q0, q1 = stream.quaternions[i0], stream.quaternions[i1]
        q1 = np.where(np.sum(q0 * q1, axis=-1, keepdims=True) < 0, -q1, q1)
        with np.errstate(invalid="ignore"):  # NaN in invalid samples stays NaN
            positions = np.where(on_sample, pos0, (1 - frac) * pos0 + frac * pos1)
            blend = (1 - frac) * q0 + frac * q1
            quaternions = np.where(
                on_sample, q0, blend / np.linalg.norm(blend, axis=-1, keepdims=True)
            )
        valid = stream.valid[i0] & (stream.valid[i1] | on_sample[..., 0])
        target = target_mask(stream, self.devices)
        return stream.replace(
            positions=np.where(target[:, None], positions, stream.positions),
            quaternions=np.where(target[:, None], quaternions, stream.quaternions),
            valid=np.where(target, valid, stream.valid),
        )


@dataclass(frozen=True)
class Drift:
    """A slow random walk: positions wander by ``position_m_per_sqrt_s`` per axis after one
    second (standard deviation grows with the square root of time), headings (about +Z) by
    ``yaw_rad_per_sqrt_s``. Both start at zero at the first sample."""

    position_m_per_sqrt_s: float = 0.001
    yaw_rad_per_sqrt_s: float = 0.0
    devices: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        check_non_negative(self, "position_m_per_sqrt_s", "yaw_rad_per_sqrt_s")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        dt = np.concatenate([[0.0], np.clip(np.diff(stream.timestamps), 0.0, None)])
        scale = np.sqrt(dt)[:, None]
        target = target_mask(stream, self.devices)[None, :]
        t, d = stream.valid.shape
        walk = np.cumsum(rng.normal(0.0, 1.0, (t, d, 3)) * scale[..., None], axis=0)
        yaw = np.cumsum(rng.normal(0.0, 1.0, (t, d)) * scale, axis=0)
        walk *= self.position_m_per_sqrt_s * target[..., None]
        yaw *= self.yaw_rad_per_sqrt_s * target
        turn = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), yaw)
        return stream.replace(
            positions=stream.positions + walk,
            quaternions=quat.mul(turn, stream.quaternions),
        )


@dataclass(frozen=True)
class TimestampJitter:
    """Gaussian noise of ``sigma_s`` on the reported timestamps (clock and transport jitter);
    the poses stay those of the nominal sample instants. A sigma comparable to the sample
    period reorders timestamps, which :meth:`TrackingStream.validate` reports."""

    sigma_s: float = 0.0002
    devices: tuple[str, ...] | None = None  # timestamps are shared: only None is meaningful

    def __post_init__(self) -> None:
        check_non_negative(self, "sigma_s")
        if self.devices is not None:
            raise DeviceError("TimestampJitter acts on the shared clock; leave devices=None")

    def apply(self, stream: TrackingStream, rng: np.random.Generator) -> TrackingStream:
        return stream.replace(
            timestamps=stream.timestamps + rng.normal(0.0, self.sigma_s, stream.n_samples)
        )


# Lighthouse-grade jitter and drift (the defaults above) and one 90 Hz frame of tracking
# latency; latency first, since it shifts whole samples. What ``noise = "realistic"`` means
# in scenarios and dataset configs.
REALISTIC_NOISE = (Latency(seconds=1 / 90), PositionJitter(), RotationJitter(), Drift())

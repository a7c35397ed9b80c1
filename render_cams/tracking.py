"""``TrackingStream``: poses of tracked devices over time, with a validity mask.

Shapes: ``T`` samples, ``D`` devices. ``timestamps (T,)`` seconds (per sample; they may
jitter), ``positions (T, D, 3)`` metres in the world frame (Z up), ``quaternions (T, D, 4)``
wxyz, ``valid (T, D)`` bool. Invalid samples hold NaN, so a consumer that ignores the mask
fails loudly instead of using stale data. ``meta`` records how the stream was made (seed,
rate, offsets, noise settings) and must be JSON-serialisable.

A stream from a simulated device is well formed; fault injection can make it otherwise on
purpose (NaN marked valid, out-of-order or duplicate timestamps). :meth:`validate` says what
is wrong, :meth:`repaired` is the clean-up every consumer can run first.
"""

from __future__ import annotations

import json
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.fileio import atomic_file

# Fixed zip entry time so that the same stream always gives the same file bytes.
_ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)
_ARRAYS = ("device_names", "timestamps", "positions", "quaternions", "valid")
# A timestamp this far from its neighbours' clock is a glitch: transport jitter is milliseconds
# and out-of-order packets are off by a period or two, so 1 s leaves a wide margin.
CLOCK_TOLERANCE_S = 1.0


class StreamError(AvatarsimError, ValueError):
    """A tracking stream breaks its contract (shapes, order of timestamps, NaN marked valid)."""


class StreamFormatError(StreamError):
    """A stream file cannot be read: missing, not an npz, missing arrays or bad metadata."""

    def __init__(self, message: str, path: str | Path):
        self.path = str(path)
        self.reason = message
        super().__init__(f"{self.path}: {message}")


class UnknownDeviceError(AvatarsimError, KeyError):
    """A device name that the stream or setup does not have."""

    def __init__(self, name: str, available: tuple[str, ...] | list[str]):
        self.name = name
        super().__init__(f"unknown device {name!r}; available: {', '.join(available)}")

    def __str__(self) -> str:  # KeyError would repr() the message
        return self.args[0]


def clock_outliers(
    timestamps: np.ndarray, tolerance_s: float = CLOCK_TOLERANCE_S, half_window: int = 8
) -> np.ndarray:
    """``(T,)`` bool: timestamps that disagree with the clock of their arrival neighbours.

    A device delivers samples in order at a steady period ``p`` (the median step between
    distinct sorted stamps), so around arrival ``i`` the stamps follow ``t_j ≈ c + j·p``. The
    local offset ``c`` is the median of ``t_j - j·p`` over the ``2·half_window + 1`` arrivals
    centred on ``i`` (fewer at the ends); a stamp further than ``tolerance_s`` from
    ``c + i·p`` is a glitch (e.g. a garbage clock value of 1000 s in a 2 s stream). A median,
    not a global fit, so that a genuine pause in delivery keeps both sides: a run of at least
    ``half_window + 1`` consistent arrivals is its own majority.

    Args:
        timestamps: ``(T,)`` finite seconds, in arrival order.
    """
    ts = np.asarray(timestamps, float)
    steps = np.diff(np.unique(ts))
    if steps.size == 0:
        return np.zeros(ts.shape, bool)
    period = float(np.median(steps))
    index = np.arange(ts.size)
    offsets = np.pad(ts - index * period, half_window, constant_values=np.nan)
    windows = np.lib.stride_tricks.sliding_window_view(offsets, 2 * half_window + 1)
    expected = np.nanmedian(windows, axis=1) + index * period
    return np.abs(ts - expected) > tolerance_s


@dataclass(frozen=True, eq=False)
class TrackingStream:
    """Device poses over time. See the module docstring for shapes and conventions.

    Arrays are copied on construction and made read-only; use :meth:`replace` to change one.
    Construction checks only that the arrays fit together; :meth:`validate` checks the rest.
    """

    device_names: tuple[str, ...]
    timestamps: np.ndarray
    positions: np.ndarray
    quaternions: np.ndarray
    valid: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = tuple(str(n) for n in self.device_names)
        arrays = {
            "timestamps": np.array(self.timestamps, dtype=float),
            "positions": np.array(self.positions, dtype=float),
            "quaternions": np.array(self.quaternions, dtype=float),
            "valid": np.array(self.valid, dtype=bool),
        }
        if len(set(names)) != len(names):
            raise StreamError(f"device names must be unique, got {names}")
        for key, arr in arrays.items():
            arr.setflags(write=False)
            object.__setattr__(self, key, arr)
        object.__setattr__(self, "device_names", names)
        object.__setattr__(self, "meta", dict(self.meta))
        self._check_shapes()

    # -- lookup ---------------------------------------------------------------------------
    @property
    def n_samples(self) -> int:
        return self.timestamps.shape[0]

    @property
    def n_devices(self) -> int:
        return len(self.device_names)

    @property
    def rate_hz(self) -> float | None:
        """Nominal sampling rate from ``meta`` (None when the producer did not record one)."""
        rate = self.meta.get("rate_hz")
        return None if rate is None else float(rate)

    def device(self, name: str) -> int:
        """Index of device ``name`` along the ``D`` axis."""
        try:
            return self.device_names.index(name)
        except ValueError:
            raise UnknownDeviceError(name, self.device_names) from None

    def replace(self, **changes: Any) -> TrackingStream:
        kw = {
            "device_names": self.device_names,
            "timestamps": self.timestamps,
            "positions": self.positions,
            "quaternions": self.quaternions,
            "valid": self.valid,
            "meta": self.meta,
        }
        kw.update(changes)
        return TrackingStream(**kw)

    # -- time -----------------------------------------------------------------------------
    def __getitem__(self, samples: slice | np.ndarray | list[int]) -> TrackingStream:
        """The samples selected by a slice, index array or boolean mask along ``T``."""
        return self.replace(
            timestamps=self.timestamps[samples],
            positions=self.positions[samples],
            quaternions=self.quaternions[samples],
            valid=self.valid[samples],
        )

    def between(self, start_s: float, stop_s: float) -> TrackingStream:
        """Samples with ``start_s <= timestamp < stop_s``, in stored order."""
        return self[(self.timestamps >= start_s) & (self.timestamps < stop_s)]

    # -- checks ---------------------------------------------------------------------------
    def _check_shapes(self) -> None:
        t, d = self.timestamps.shape[:1], self.n_devices
        expected = {
            "timestamps": t,
            "positions": (*t, d, 3),
            "quaternions": (*t, d, 4),
            "valid": (*t, d),
        }
        for key, shape in expected.items():
            got = getattr(self, key).shape
            if self.timestamps.ndim != 1 or got != shape:
                raise StreamError(
                    f"{key} must have shape {shape} for {d} devices and "
                    f"{self.timestamps.shape[0]} timestamps, got {got}"
                )

    def validate(self) -> TrackingStream:
        """Raise :class:`StreamError` on the first broken rule; return ``self`` when sound.

        Rules: shapes agree; timestamps are finite and strictly increasing; every sample marked
        valid has a finite position and a finite unit quaternion.
        """
        self._check_shapes()
        ts = self.timestamps
        if not np.all(np.isfinite(ts)):
            bad = np.flatnonzero(~np.isfinite(ts))
            raise StreamError(f"{bad.size} timestamps are NaN/inf (first at sample {bad[0]})")
        steps = np.diff(ts)
        if np.any(steps <= 0):
            i = int(np.flatnonzero(steps <= 0)[0])
            raise StreamError(
                f"timestamps must strictly increase: sample {i + 1} at {ts[i + 1]:.6f} s follows "
                f"{ts[i]:.6f} s ({int(np.sum(steps <= 0))} such steps); use .repaired()"
            )
        finite = np.isfinite(self.positions).all(-1) & np.isfinite(self.quaternions).all(-1)
        broken = self.valid & ~finite
        if np.any(broken):
            t, d = np.argwhere(broken)[0]
            raise StreamError(
                f"{int(broken.sum())} samples are marked valid but hold NaN/inf (first: device "
                f"{self.device_names[d]!r} at sample {t}); use .repaired()"
            )
        norms = np.linalg.norm(self.quaternions[self.valid], axis=-1)
        if norms.size and np.max(np.abs(norms - 1.0)) > 1e-6:
            raise StreamError(f"valid quaternions must be unit length; worst norm {norms.max():g}")
        return self

    def repaired(self) -> TrackingStream:
        """A stream that passes :meth:`validate`, for consumers of untrusted input.

        Samples are stably sorted by timestamp; samples with a non-finite or repeated timestamp
        (the first arrival is kept) or a glitched one (:func:`clock_outliers`) are dropped, and
        non-finite poses are marked invalid and NaN-filled. ``meta["repairs"]`` counts what
        was changed.
        """
        finite = np.flatnonzero(np.isfinite(self.timestamps))
        glitched = clock_outliers(self.timestamps[finite])
        keep = finite[~glitched]
        order = keep[np.argsort(self.timestamps[keep], kind="stable")]
        ts = self.timestamps[order]
        first = np.concatenate([[True], np.diff(ts) > 0]) if ts.size else np.zeros(0, bool)
        order = order[first]
        out = self[order]
        finite = np.isfinite(out.positions).all(-1) & np.isfinite(out.quaternions).all(-1)
        valid = out.valid & finite
        repairs = {
            "reordered": int(np.sum(np.diff(order) < 0)),
            "dropped_samples": int(self.n_samples - order.size),
            "invalidated": int(np.sum(out.valid & ~finite)),
            "clock_outliers": int(glitched.sum()),
        }
        return out.replace(
            positions=np.where(valid[..., None], out.positions, np.nan),
            quaternions=np.where(valid[..., None], out.quaternions, np.nan),
            valid=valid,
            meta={**self.meta, "repairs": repairs},
        )

    # -- files ----------------------------------------------------------------------------
    def to_npz(self, path: str | Path) -> Path:
        """Write an ``.npz`` atomically (temporary file + rename); same stream => same bytes."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        entries = {
            "device_names": np.array(self.device_names, dtype=str),
            "timestamps": self.timestamps,
            "positions": self.positions,
            "quaternions": self.quaternions,
            "valid": self.valid,
            "meta": np.array(json.dumps(self.meta, sort_keys=True)),
        }
        with atomic_file(path) as fh:
            with zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as zf:
                for key, arr in entries.items():
                    info = zipfile.ZipInfo(f"{key}.npy", date_time=_ZIP_EPOCH)
                    info.compress_type = zipfile.ZIP_DEFLATED
                    with zf.open(info, "w") as entry:
                        np.lib.format.write_array(entry, np.asarray(arr), allow_pickle=False)
            fh.flush()
            os.fsync(fh.fileno())
        return path

    @classmethod
    def from_npz(cls, path: str | Path) -> TrackingStream:
        """Read a stream written by :meth:`to_npz`; :class:`StreamFormatError` if malformed."""
        path = Path(path)
        if not path.is_file():
            raise StreamFormatError("no such stream file", path)
        try:
            with np.load(path, allow_pickle=False) as data:
                missing = [k for k in (*_ARRAYS, "meta") if k not in data.files]
                if missing:
                    raise StreamFormatError(f"not a tracking stream: lacks {missing}", path)
                arrays = {k: data[k] for k in _ARRAYS}
                meta = json.loads(str(data["meta"]))
        except StreamFormatError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise StreamFormatError(f"unreadable npz ({type(exc).__name__}: {exc})", path) from exc
        if not isinstance(meta, dict):
            raise StreamFormatError("meta must be a JSON object", path)
        try:
            return cls(
                device_names=tuple(arrays["device_names"].reshape(-1).tolist()),
                timestamps=arrays["timestamps"],
                positions=arrays["positions"],
                quaternions=arrays["quaternions"],
                valid=arrays["valid"],
                meta=meta,
            )
        except StreamError as exc:
            raise StreamFormatError(str(exc), path) from exc

    def __repr__(self) -> str:
        return (
            f"TrackingStream(devices={list(self.device_names)}, samples={self.n_samples}, "
            f"valid={self.valid.mean() if self.valid.size else 0:.1%})"
        )

"""Scalar time curves shared by the activities: easing, swing arcs, periodic phases.

All functions are vectorised: ``u`` is any array of normalised times, output has its shape.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d


def smoothstep(u: np.ndarray) -> np.ndarray:
    """Cubic ease ``3u^2 - 2u^3`` on ``[0, 1]`` (clamped outside), zero slope at both ends."""
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def minimum_jerk(u: np.ndarray) -> np.ndarray:
    """Minimum-jerk progress ``10u^3 - 15u^4 + 6u^5`` (Flash & Hogan 1985), clamped to [0, 1].

    Zero velocity and acceleration at both ends: the shape of human point-to-point reaches.
    """
    u = np.clip(u, 0.0, 1.0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


def window(u: np.ndarray, start: float, stop: float) -> np.ndarray:
    """``u`` rescaled so that ``[start, stop]`` maps to ``[0, 1]``, clamped."""
    return np.clip((u - start) / (stop - start), 0.0, 1.0)


def swing_progress(tau: np.ndarray, lift: float) -> np.ndarray:
    """Horizontal progress of a swinging foot or hand over ``tau in [0, 1]``.

    The limb first rises straight up for ``lift`` of the swing, travels with a minimum-jerk
    profile, and comes straight down for the last ``lift``: a point near its support surface
    never slides, because horizontal travel only happens while it is lifted.
    """
    return minimum_jerk(window(tau, lift, 1.0 - lift))


def bump(tau: np.ndarray) -> np.ndarray:
    """``sin(pi tau)`` on ``[0, 1]``, zero outside: the height profile of a swing."""
    tau = np.clip(tau, 0.0, 1.0)
    return np.sin(np.pi * tau)


def phase(
    times: np.ndarray, frequency: float, offset: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Cycle index ``(T,) int`` and phase in ``[0, 1)`` of a periodic action (phase ``offset``
    at t = 0)."""
    cycles = times * frequency + offset
    index = np.floor(cycles)
    return index.astype(np.int64), cycles - index


def keyframes(times: np.ndarray, key_times: np.ndarray, key_values: np.ndarray) -> np.ndarray:
    """Values ``(T, ...)`` eased between keyframes ``key_values (K, ...)`` at ``key_times (K,)``.

    Each segment uses minimum-jerk progress, so the curve rests at every key (poses are held,
    then moved through): the rhythm of deliberate movements such as punches or kicks.
    """
    key_times = np.asarray(key_times, dtype=float)
    key_values = np.asarray(key_values, dtype=float)
    seg = np.clip(np.searchsorted(key_times, times, side="right") - 1, 0, len(key_times) - 2)
    u = (times - key_times[seg]) / (key_times[seg + 1] - key_times[seg])
    s = minimum_jerk(u).reshape((-1,) + (1,) * (key_values.ndim - 1))
    return key_values[seg] * (1.0 - s) + key_values[seg + 1] * s


def smooth_cap(values: np.ndarray, cap: np.ndarray, fps: float, half_width_s: float) -> np.ndarray:
    """``values (T,)`` lowered smoothly so that they never exceed ``cap (T,)``.

    The needed drop ``max(values - cap, 0)`` is first dilated (running maximum over
    ``+-half_width_s``), then averaged with a Hann window of the same half-width. Every value
    in the window is at least the drop at its centre, so the result stays under ``cap``; and
    a Hann window is C1, so its convolution with the (stepwise) dilated drop is C2: continuous
    velocity and acceleration, unlike ``np.minimum(values, cap)`` whose kinks are
    accelerations of many g for a body whose pelvis is clamped to its leg reach.
    """
    drop = np.maximum(values - cap, 0.0)
    half = max(int(round(half_width_s * fps)), 1)
    dilated = maximum_filter1d(drop, 2 * half + 1, mode="nearest")
    kernel = np.hanning(2 * half + 3)[1:-1]
    padded = np.pad(dilated, half, mode="edge")
    return values - np.convolve(padded, kernel / kernel.sum(), mode="valid")

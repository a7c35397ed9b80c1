"""Face: lip sync from audio and procedural blinking (MoveBox §III-A3, §IV-B2).

Lip sync (§III-A3): MoveBox "uses the spectral frequency of the microphone input to
proportionally move two joints on the rigged face: the jaw and the upper lip". Per animation
frame we take the magnitude spectrum of the audio around it (Hann window, two frames long) and
its mean amplitude in two bands: below 1 kHz, where vowels carry most of their energy, for the
jaw, and 1-4 kHz (consonants, fricative onsets) for the upper lip. Each is divided by its
running peak so far (causal, as for a live microphone), gated to zero under
``GATE_FRACTION`` of that peak (silence closes the mouth), and eased with a short attack and
release. The avatar rig has a jaw but no upper-lip bone: the jaw is driven and the upper-lip
opening is returned as a channel for rigs that have one.

Blinking (§IV-B2: "basic blinking idling"): blinks come as a Poisson process at a human
spontaneous blink rate, with a minimum gap, each a fast close and a slower reopen. Rates:
Bentivoglio et al., "Analysis of blink rate patterns in normal subjects", Movement Disorders
12(6):1028-1034, 1997: 17 blinks/min at rest, 26 in conversation, 4.5 while reading.
Duration (lid closing about 100 ms, reopening slower, whole blink 100-400 ms): VanderWerf et
al., "Eyelid movements: behavioral studies of blinking in humans under different stimulus
conditions", J. Neurophysiology 89:2784-2796, 2003.

Shapes: ``T`` animation frames, ``S`` audio samples.
"""

from __future__ import annotations

import struct
import warnings
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.io import wavfile

from avatarsim.avatar_models import Motion, Skeleton, quat
from avatarsim.synthesis.base import SynthesisError

JAW_BAND_HZ = (80.0, 1000.0)
LIP_BAND_HZ = (1000.0, 4000.0)
GATE_FRACTION = 0.1
"""Amplitude under this share of the running peak counts as silence (our choice; the audio
README's silent stretches are under 2% RMS)."""
PEAK_FLOOR = 1e-6
"""Running-peak floor, so that leading silence does not divide by zero."""
ATTACK_S, RELEASE_S = 0.015, 0.025
"""Time constants of the mouth opening and closing (our choice)."""
JAW_OPEN_RAD = np.deg2rad(18.0)
"""Jaw rotation at full opening (our choice; speech jaw opening stays under ~20 degrees)."""
BLINK_RATES_PER_MIN = {"rest": 17.0, "conversation": 26.0, "reading": 4.5}
"""Spontaneous blink rates, Bentivoglio et al. 1997 (module docstring)."""
BLINK_CLOSE_S, BLINK_OPEN_S = 0.1, 0.2
"""Lid closing and reopening times, VanderWerf et al. 2003 (module docstring)."""
MIN_BLINK_GAP_S = 0.5
"""No two blinks closer than this (our choice; keeps blinks apart)."""
EYELID_CLOSED_RAD = np.deg2rad(35.0)
"""Eyelid rotation when closed (our choice)."""
JAW, EYELIDS = "Bip01 Jaw", ("Bip01 L Eyelid", "Bip01 R Eyelid")
OPEN_AXIS = np.array([0.0, 1.0, 0.0])
"""Jaw and eyelids turn about their local +y (left) axis: +x (forward) goes down."""


MIN_RATE_HZ = 2 * LIP_BAND_HZ[1]
"""The lowest sampling rate lip sync can use: the upper-lip band reaches 4 kHz, which only a
rate of twice that holds (Nyquist); 8 kHz is telephone audio, the lowest common PCM rate."""
MAX_RATE_HZ = 384_000
"""The highest PCM rate of studio converters; a window two frames long holds ``2 rate / fps``
samples, so a header claiming more would take memory for nothing."""


class AudioFormatError(SynthesisError):
    """An audio file that is not a readable PCM WAV."""


def read_wav(path: str | Path) -> tuple[int, np.ndarray]:
    """``(rate_hz, samples (S,))``: a WAV file as mono float in [-1, 1].

    Raises:
        AudioFormatError: no such file, not a WAV, truncated (fewer samples than its header
            declares), a rate outside :data:`MIN_RATE_HZ`-:data:`MAX_RATE_HZ`, no samples or
            non-finite ones.
    """
    path = Path(path)
    if not path.is_file():
        raise AudioFormatError(f"{path}: no such audio file")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", wavfile.WavFileWarning)
            rate, data = wavfile.read(path)
    except (ValueError, EOFError, wave.Error, struct.error) as exc:
        raise AudioFormatError(
            f"{path}: unknown audio format ({exc}); give a PCM WAV file"
        ) from exc
    truncated = [str(w.message) for w in caught if "EOF" in str(w.message)]
    if truncated:
        raise AudioFormatError(f"{path}: truncated WAV file ({truncated[0]})")
    if not MIN_RATE_HZ <= rate <= MAX_RATE_HZ:
        raise AudioFormatError(
            f"{path}: sampling rate {rate} Hz; lip sync needs {MIN_RATE_HZ:g}-{MAX_RATE_HZ} Hz "
            "(its upper-lip band reaches 4 kHz)"
        )
    if data.size == 0:
        raise AudioFormatError(f"{path}: the WAV file has no samples")
    if data.dtype.kind == "f" and not np.isfinite(data).all():
        raise AudioFormatError(f"{path}: the WAV file holds NaN or infinite samples")
    if data.dtype == np.uint8:  # 8-bit WAV is unsigned, centred on 128
        samples = (data.astype(float) - 128.0) / 128.0
    elif np.issubdtype(data.dtype, np.integer):
        samples = data.astype(float) / float(np.iinfo(data.dtype).max)
    else:
        samples = data.astype(float)
    return int(rate), samples.mean(axis=1) if samples.ndim == 2 else samples


def band_amplitudes(samples: np.ndarray, rate_hz: int, fps: float) -> np.ndarray:
    """``(T, 2)`` mean spectral magnitude in :data:`JAW_BAND_HZ` and :data:`LIP_BAND_HZ` of a
    Hann window two frames long centred on each frame ``t / fps``."""
    half = int(round(rate_hz / fps))
    n_frames = int(np.floor(samples.size / rate_hz * fps)) + 1
    padded = np.pad(samples, half)
    starts = (np.arange(n_frames) * rate_hz / fps).astype(int)
    windows = padded[starts[:, None] + np.arange(2 * half)[None]] * np.hanning(2 * half)
    spectrum = np.abs(np.fft.rfft(windows, axis=1)) / half
    freqs = np.fft.rfftfreq(2 * half, 1.0 / rate_hz)
    bands = [(freqs >= lo) & (freqs < hi) for lo, hi in (JAW_BAND_HZ, LIP_BAND_HZ)]
    return np.stack([spectrum[:, b].mean(axis=1) for b in bands], axis=1)


def ease(target: np.ndarray, fps: float) -> np.ndarray:
    """``(T, C)`` openings following ``target`` with the attack time constant while the
    target rises and the release one while it falls (one pass, per channel)."""
    up = 1.0 - np.exp(-1.0 / (fps * ATTACK_S))
    down = 1.0 - np.exp(-1.0 / (fps * RELEASE_S))
    out = np.empty_like(target)
    level = np.zeros(target.shape[1:])
    for t in range(target.shape[0]):  # attack/release switch per sample: a recursive filter
        rate = np.where(target[t] > level, up, down)
        level = level + rate * (target[t] - level)
        out[t] = level
    return out


@dataclass(frozen=True, eq=False)
class LipSync:
    """Mouth openings in ``[0, 1]`` over time.

    Attributes:
        fps: animation rate.
        jaw: ``(T,)`` jaw opening. upper_lip: ``(T,)`` upper-lip opening.
    """

    fps: float
    jaw: np.ndarray
    upper_lip: np.ndarray


def lip_sync(samples: np.ndarray, rate_hz: int, fps: float = 30.0) -> LipSync:
    """Jaw and upper-lip openings for audio ``samples (S,)`` (module docstring)."""
    amplitude = band_amplitudes(np.asarray(samples, float), rate_hz, fps)
    peak = np.maximum(np.maximum.accumulate(amplitude, axis=0), PEAK_FLOOR)
    level = amplitude / peak
    gated = np.where(level < GATE_FRACTION, 0.0, (level - GATE_FRACTION) / (1 - GATE_FRACTION))
    eased = ease(gated, fps)
    return LipSync(float(fps), eased[:, 0], eased[:, 1])


def blinks(
    duration_s: float, fps: float, rng: np.random.Generator, activity: str = "conversation"
) -> np.ndarray:
    """``(T,)`` eyelid closure in ``[0, 1]`` (1 closed) with blinks at the cited rate of
    ``activity`` (``rest``, ``conversation``, ``reading``)."""
    if activity not in BLINK_RATES_PER_MIN:
        raise SynthesisError(
            f"unknown blink activity {activity!r}; known: {list(BLINK_RATES_PER_MIN)}"
        )
    mean_gap = 60.0 / BLINK_RATES_PER_MIN[activity]
    n = int(np.ceil(duration_s / MIN_BLINK_GAP_S)) + 2
    # Exponential gaps above the minimum, with the mean gap the cited rate gives.
    gaps = MIN_BLINK_GAP_S + rng.exponential(mean_gap - MIN_BLINK_GAP_S, n)
    onsets = np.cumsum(gaps) - gaps[0] * rng.uniform()
    t = np.arange(int(np.floor(duration_s * fps)) + 1) / fps
    # Blinks never overlap (the minimum gap outlasts one), so each frame sees the last onset.
    last = np.searchsorted(onsets, t, side="right") - 1
    since = np.where(last >= 0, t - onsets[np.maximum(last, 0)], np.inf)
    closing = np.clip(since / BLINK_CLOSE_S, 0.0, 1.0)
    opening = np.clip(1.0 - (since - BLINK_CLOSE_S) / BLINK_OPEN_S, 0.0, 1.0)
    return np.where(since < BLINK_CLOSE_S, closing, opening)


def face_motion(skeleton: Skeleton, fps: float, jaw: np.ndarray, closure: np.ndarray) -> Motion:
    """A motion on the avatar ``skeleton`` at rest but for the face: jaw opening ``jaw (T,)``
    and eyelid ``closure (T,)`` (the shorter is held at its last value); mask it onto a body
    with :func:`~synthesis.movebox.masks.compose` and the ``face`` set."""
    n = max(jaw.size, closure.size)
    jaw = np.pad(jaw, (0, n - jaw.size), mode="edge")
    closure = np.pad(closure, (0, n - closure.size), mode="edge")
    rot = np.tile(quat.IDENTITY, (n, skeleton.n_joints, 1))
    rot[:, skeleton.index(JAW)] = quat.from_axis_angle(OPEN_AXIS, jaw * JAW_OPEN_RAD)
    lids = quat.from_axis_angle(OPEN_AXIS, closure * EYELID_CLOSED_RAD)
    rot[:, skeleton.indices(list(EYELIDS))] = lids[:, None]
    root = np.tile(skeleton.offsets[0], (n, 1))
    return Motion(skeleton, fps, root, rot, meta={"face": "lip sync and blinking"})

"""Lip sync on the speech samples (jaw follows the RMS envelope, closed in the listed
silences), WAV reading errors, and blinking at the cited rate."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.rigs import load_rig
from avatarsim.synthesis.movebox.face import (
    BLINK_RATES_PER_MIN,
    AudioFormatError,
    blinks,
    face_motion,
    lip_sync,
    read_wav,
)

SILENCES = {  # ../shared/audio/README.md: 10 ms RMS under 2% of the peak
    "hello.wav": [(0.53, 0.72), (2.65, 3.07)],
    "story.wav": [(1.36, 1.59), (4.11, 4.34), (5.33, 5.63)],
}
CLOSING_S, OPENING_S = 0.1, 0.05
"""The mouth needs time to close after speech and opens just before the next sound (the
analysis window is two frames long): the silent stretches are checked inside these margins."""


def rms_envelope(samples: np.ndarray, rate: int, times: np.ndarray) -> np.ndarray:
    hop = rate // 100
    n = samples.size // hop
    rms = np.sqrt(np.mean(samples[: n * hop].reshape(n, hop) ** 2, axis=1))
    return np.interp(times, (np.arange(n) + 0.5) / 100, rms)


@pytest.mark.parametrize("name", sorted(SILENCES))
def test_jaw_follows_speech_and_closes_in_silence(audio_dir, name):
    rate, samples = read_wav(audio_dir / name)
    sync = lip_sync(samples, rate, 30.0)
    t = np.arange(sync.jaw.size) / 30.0
    r = np.corrcoef(sync.jaw, rms_envelope(samples, rate, t))[0, 1]
    assert r > 0.6  # measured: hello 0.737, story 0.880 (30 fps); 0.764, 0.868 at 90 fps
    for start, stop in SILENCES[name]:
        inside = (t >= start + CLOSING_S) & (t <= stop - OPENING_S)
        assert inside.any()
        assert sync.jaw[inside].max() < 0.1 * sync.jaw.max()  # measured at most 0.5%


@pytest.mark.parametrize(
    ("content", "reason"),
    [(b"", "unknown audio format"), (b"ID3\x03\x00 not a wav at all", "unknown audio format")],
)
def test_unreadable_audio_raises(tmp_path, content, reason):
    path = tmp_path / "speech.mp3"
    path.write_bytes(content)
    with pytest.raises(AudioFormatError, match=reason):
        read_wav(path)
    with pytest.raises(AudioFormatError, match="no such audio file"):
        read_wav(tmp_path / "absent.wav")


@pytest.mark.parametrize("activity", sorted(BLINK_RATES_PER_MIN))
def test_blink_rate_matches_the_cited_rate(activity):
    minutes = 20.0
    closure = blinks(60.0 * minutes, 30.0, np.random.default_rng(0), activity)
    assert 0.0 <= closure.min() and 0.7 < closure.max() <= 1.0
    onsets = np.sum(np.diff((closure > 0.5).astype(int)) == 1)
    cited = BLINK_RATES_PER_MIN[activity]
    # Bentivoglio et al. 1997: rest 17, conversation 26, reading 4.5 blinks/min; seeds 0-4
    # counted 14.9-18.3, 24.0-27.9 and 4.0-4.7 per min over 20 min (Poisson spread).
    assert onsets / minutes == pytest.approx(cited, rel=0.15)


def test_face_motion_moves_only_the_face():
    sk = load_rig("avatar").skeleton
    m = face_motion(sk, 30.0, np.array([0.0, 1.0]), np.array([0.0, 1.0, 0.0]))
    assert m.n_frames == 3
    moving = np.flatnonzero(~np.all(np.isclose(m.local_rot, [1, 0, 0, 0]), axis=(0, 2)))
    assert {sk.names[j] for j in moving} == {"Bip01 Jaw", "Bip01 L Eyelid", "Bip01 R Eyelid"}
    # the chin goes down when the jaw opens
    chin = sk.index("Bip01 JawNub")
    assert m.global_positions()[1, chin, 2] < m.global_positions()[0, chin, 2]


@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.int32, np.float32])
def test_wav_sample_formats_read_as_unit_floats(tmp_path, dtype):
    from scipy.io import wavfile

    tone = np.sin(np.linspace(0, 20 * np.pi, 800))
    if dtype == np.uint8:
        data = np.round(128 + 127 * tone).astype(dtype)
    elif np.issubdtype(dtype, np.integer):
        data = np.round(np.iinfo(dtype).max * tone).astype(dtype)
    else:
        data = tone.astype(dtype)
    wavfile.write(tmp_path / "tone.wav", 8000, np.stack([data, data], axis=1))  # stereo
    rate, samples = read_wav(tmp_path / "tone.wav")
    assert rate == 8000 and samples.shape == (800,)
    assert np.allclose(samples, tone, atol=0.02)

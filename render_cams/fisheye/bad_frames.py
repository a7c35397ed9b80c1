"""Bad frames of analog wireless cameras: injection with ground truth, and a detector.

ControllerPose §4.2: the analog transmissions "suffer from interference and occasional
synchronization loss, resulting in unusable frames (roughly 1 in 50) that we filter". Three
kinds are injected here, as they look on analog receivers:

- ``noise_band``: one to three horizontal bands of strong snow (interference bursts);
- ``tearing``: lost horizontal sync: from a random row down, the picture is shifted sideways
  (wrapping) and a bright retrace line marks the tear;
- ``black``: lost vertical sync / carrier: a near-black frame with faint noise.

Defects the detector was not designed around, used to measure it (:data:`UNSEEN_KINDS`):

- ``motion_blur``: the controller swung fast within the exposure;
- ``hand_in_view``: the other hand a few centimetres from the lens fills much of the view;
- ``saturation``: overexposure, the receiver's gain hunting.

The detector needs no training data: a black frame has a low mean; a noise band raises the
high-frequency energy of some rows far above the robust (median / MAD) level of the sequence;
a tear shows its saturated retrace line.
"""

from __future__ import annotations

import cv2
import numpy as np

from avatarsim.render_cams.device import DeviceError

BAD_FRAME_RATE = 1.0 / 50.0  # ControllerPose §4.2
KINDS = ("noise_band", "tearing", "black")
UNSEEN_KINDS = ("motion_blur", "hand_in_view", "saturation")  # not designed for: measured only
Z_THRESHOLD = 50.0  # robust z-score of row snow energy above which a frame is flagged
BLACK_LEVEL = 30.0  # mean grey level (0-255) below which a frame counts as black
SATURATED = 250.0  # grey level of a saturated pixel
RETRACE_SHARE = 0.9  # a row this saturated is a retrace line (torn frame)


def noise_band(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One to three horizontal bands of strong snow over ``frame`` ``(H, W, 3)`` float32."""
    h = frame.shape[0]
    for _ in range(rng.integers(1, 4)):
        top = rng.integers(0, h)
        height = max(2, int(h * rng.uniform(0.05, 0.2)))
        band = frame[top : top + height]
        snow = rng.normal(128.0, 70.0, band.shape[:2])[..., None]
        frame[top : top + height] = 0.3 * band + 0.7 * snow
    return frame


def tearing(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """From a random row down, the picture shifted sideways, a saturated retrace line on top."""
    h, w = frame.shape[:2]
    row = rng.integers(h // 8, 7 * h // 8)
    frame[row:] = np.roll(frame[row:], rng.integers(w // 6, w // 2), axis=1)
    frame[row : row + 2] = 255.0  # saturated retrace line
    return frame


def black(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A near-black frame with faint noise (lost vertical sync or carrier)."""
    noise = 12.0 + 4.0 * rng.standard_normal(frame.shape[:2])
    return np.broadcast_to(noise[..., None], frame.shape)


def motion_blur(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A fast swing of the controller within the exposure: a linear blur 5-15 % of the
    image width long, in a random direction."""
    length = max(3, int(frame.shape[1] * rng.uniform(0.05, 0.15)))
    kernel = np.zeros((length, length), np.float32)
    kernel[length // 2] = 1.0 / length
    turn = cv2.getRotationMatrix2D(((length - 1) / 2, (length - 1) / 2), rng.uniform(0, 180), 1.0)
    kernel = cv2.warpAffine(kernel, turn, (length, length))
    return cv2.filter2D(frame, -1, kernel / max(kernel.sum(), 1e-6))


def hand_in_view(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The other hand a few centimetres from the lens, out of focus: a blurred, shaded
    skin-coloured blob over 30-70 % of the image, entering from a random side."""
    h, w = frame.shape[:2]
    v, u = np.mgrid[0:h, 0:w].astype(np.float32)
    side = rng.uniform(0, 2 * np.pi)
    centre = np.array([w / 2 + 0.45 * w * np.cos(side), h / 2 + 0.45 * h * np.sin(side)])
    radius = np.sqrt(rng.uniform(0.3, 0.7) * h * w / np.pi)
    gap = np.hypot(u - centre[0], (v - centre[1]) * 1.2) / radius
    cover = np.clip((1.15 - gap) / 0.3, 0.0, 1.0)[..., None]  # a soft, defocused edge
    skin = np.array([205.0, 150.0, 125.0]) * rng.uniform(0.6, 1.1)
    shade = (1.0 - 0.35 * np.clip(gap, 0, 1))[..., None]  # lit from the room, darker rim
    return (1.0 - cover) * frame + cover * skin * shade


def saturation(frame: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Overexposure (the receiver's gain hunting after a dark frame): gain 2.5-5, clipped."""
    return np.minimum(frame * rng.uniform(2.5, 5.0) + rng.uniform(0.0, 40.0), 255.0)


CORRUPTIONS = {
    "noise_band": noise_band,
    "tearing": tearing,
    "black": black,
    "motion_blur": motion_blur,
    "hand_in_view": hand_in_view,
    "saturation": saturation,
}


def inject(
    frames: np.ndarray,
    rng: np.random.Generator,
    rate: float = BAD_FRAME_RATE,
    kinds: tuple[str, ...] = KINDS,
) -> tuple[np.ndarray, np.ndarray, list[str | None]]:
    """Corrupt about ``rate`` of ``frames`` ``(T, H, W, 3)`` uint8 with defects of ``kinds``
    (default the analog faults :data:`KINDS`; :data:`UNSEEN_KINDS` to measure the filter on
    defects it was not designed around).

    Returns the corrupted copy, ``(T,)`` bool ground-truth flags and the kind per frame.
    """
    if not 0.0 <= rate <= 1.0:
        raise DeviceError(f"bad-frame rate must be in [0, 1], got {rate}")
    unknown = set(kinds) - set(CORRUPTIONS)
    if unknown or not kinds:
        raise DeviceError(f"unknown bad-frame kinds {sorted(unknown)}; known: {list(CORRUPTIONS)}")
    out = np.array(frames, dtype=np.uint8, copy=True)
    flags = rng.random(out.shape[0]) < rate
    names: list[str | None] = [None] * out.shape[0]
    for t in np.flatnonzero(flags):  # a handful of frames: the corruption is per frame
        kind = kinds[rng.integers(len(kinds))]
        names[t] = kind
        frame = CORRUPTIONS[kind](out[t].astype(np.float32), rng)
        out[t] = np.clip(frame, 0, 255).astype(np.uint8)
    return out, flags, names


def frame_features(frames: np.ndarray) -> np.ndarray:
    """``(T, 3)`` per-frame scores: mean brightness, worst-row high-frequency energy above the
    frame's median row, and the largest share of saturated pixels in a row (a retrace line)."""
    gray = np.asarray(frames, np.float32).mean(axis=-1)  # (T, H, W)
    row_hf = np.abs(np.diff(gray, axis=2)).mean(axis=2)  # (T, H)
    band = np.percentile(row_hf, 95, axis=1) - np.median(row_hf, axis=1)
    saturated_row = (gray >= SATURATED).mean(axis=2).max(axis=1)
    return np.stack([gray.mean(axis=(1, 2)), band, saturated_row], axis=1)


def detect(frames: np.ndarray, z_threshold: float = Z_THRESHOLD) -> np.ndarray:
    """``(T,)`` bool: frames that look corrupted.

    Black: mean brightness below :data:`BLACK_LEVEL`. Tear: a row more than
    :data:`RETRACE_SHARE` saturated (the retrace line). Noise band: row snow energy more than
    ``z_threshold`` robust standard deviations (median / MAD) above the sequence's level.
    """
    features = frame_features(frames)
    band = features[:, 1]
    median = np.median(band)
    mad = 1.4826 * np.median(np.abs(band - median)) + 1e-3 * (abs(median) + 1.0)
    return (
        (features[:, 0] < BLACK_LEVEL)
        | (features[:, 2] > RETRACE_SHARE)
        | ((band - median) / mad > z_threshold)
    )


def precision_recall(truth: np.ndarray, flagged: np.ndarray) -> dict:
    """Precision and recall of ``flagged`` against ``truth`` (both ``(T,)`` bool)."""
    tp = int(np.sum(truth & flagged))
    return {
        "precision": tp / max(int(flagged.sum()), 1),
        "recall": tp / max(int(truth.sum()), 1),
        "injected": int(truth.sum()),
        "flagged": int(flagged.sum()),
    }

"""The MOTION block of a BVH file: frame count, frame time and the channel values of every
frame (see :mod:`..bvh`)."""

from __future__ import annotations

import io
import warnings
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.motion import FPS_RANGE

# Bytes of frame data that the np.loadtxt fast path reads exactly as the checked path does.
_DECIMAL_BYTES = b"0123456789.+-eE \t\r\n"


def _header_line(text: str, start: int, path: Path, line: int) -> tuple[list[str], int, int]:
    """Tokens of the next non-blank line at ``text[start:]``, its line number, and its end."""
    while True:
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        tokens = text[start:end].split()
        if tokens:
            return tokens, line, end + 1
        if end >= len(text):
            raise MotionFormatError("file ends inside the MOTION header", path, line)
        start, line = end + 1, line + 1


def motion_header(
    text: str, start: int, first_line: int, path: Path
) -> tuple[int, float, int, int]:
    """Frames and Frame Time; returns (frames, frame_time, data_start, data_first_line)."""
    tokens, line, start = _header_line(text, start, path, first_line)
    if len(tokens) != 2 or tokens[0] != "Frames:" or not tokens[1].isdigit() or int(tokens[1]) < 1:
        raise MotionFormatError(
            f"expected 'Frames: N' with N >= 1, found {' '.join(tokens)!r}", path, line
        )
    frames = int(tokens[1])
    tokens, line, start = _header_line(text, start, path, line + 1)
    frame_time = float("nan")
    if len(tokens) == 3 and tokens[:2] == ["Frame", "Time:"]:
        try:
            frame_time = float(tokens[2])
        except ValueError:
            pass
    if not (np.isfinite(frame_time) and frame_time > 0):
        raise MotionFormatError(
            f"expected 'Frame Time: SECONDS' (positive), found {' '.join(tokens)!r}", path, line
        )
    lo, hi = 1.0 / FPS_RANGE[1], 1.0 / FPS_RANGE[0]
    if not lo <= frame_time <= hi:
        raise MotionFormatError(
            f"Frame Time {tokens[2]} s is not a mocap frame time ({lo:g}-{hi:g} s, i.e. "
            f"{FPS_RANGE[0]:g}-{FPS_RANGE[1]:g} fps)",
            path,
            line,
        )
    return frames, frame_time, start, line + 1


def motion_values(
    data: str, frames: int, n_channels: int, path: Path, first_line: int
) -> np.ndarray:
    """``(frames, n_channels)`` floats of the frame lines.

    Fast path: frame data of plain decimal numbers, spaces, tabs and newlines only is read by
    ``np.loadtxt`` (its C parser, a third faster than ``np.fromstring``, also checks that every
    line has as many values as the first). Anything it does not read into finite values of the
    declared shape, or any other byte, goes to :func:`checked_motion_values`, which finds the
    offending line (or reads what the fast path declined, e.g. a lone carriage return).
    """
    if not data.encode("utf-8").translate(None, _DECIMAL_BYTES):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # no data: the checked path says so
                values = np.loadtxt(io.StringIO(data), comments=None, ndmin=2)
        except ValueError:
            values = None
        if values is not None and values.shape == (frames, n_channels):
            if np.isfinite(values).all():
                return values
    return checked_motion_values(data, frames, n_channels, path, first_line)


def checked_motion_values(
    data: str, frames: int, n_channels: int, path: Path, first_line: int
) -> np.ndarray:
    """``(frames, n_channels)`` floats of the frame lines, validated line by line (vectorised)."""
    raw = np.frombuffer(data.encode("utf-8"), dtype=np.uint8)
    space = raw <= 32  # ASCII whitespace and control bytes separate values
    token_starts = np.flatnonzero(~space & np.concatenate([[True], space[:-1]]))
    newlines = np.flatnonzero(raw == 10)
    # Tokens per line from where each newline falls among the (sorted) token starts: a search
    # of the few newlines among the many tokens, not the other way round.
    per_line = np.diff(np.searchsorted(token_starts, newlines), prepend=0, append=token_starts.size)
    rows = np.flatnonzero(per_line)
    if rows.size < frames:
        last = first_line + (int(rows[-1]) if rows.size else 0)
        raise MotionFormatError(
            f"truncated: 'Frames: {frames}' but only {rows.size} frame lines", path, last
        )
    if rows.size > frames:
        raise MotionFormatError(
            f"more frame lines than 'Frames: {frames}'", path, first_line + int(rows[frames])
        )
    wrong = rows[per_line[rows] != n_channels]
    if wrong.size:
        n = int(per_line[wrong[0]])
        raise MotionFormatError(
            f"frame line has {n} values, the hierarchy declares {n_channels} channels",
            path,
            first_line + int(wrong[0]),
        )
    try:
        values = np.fromstring(data, sep=" ")  # C parser; raises on any non-number
    except ValueError:
        for k, ln in enumerate(data.split("\n")):
            for t in ln.split():
                try:
                    float(t)
                except ValueError:
                    raise MotionFormatError(
                        f"{t!r} is not a number", path, first_line + k
                    ) from None
        raise MotionFormatError("unreadable frame data", path, first_line) from None
    if values.size != frames * n_channels:  # str.split knows more whitespace than the byte count
        raise MotionFormatError("frame data contains unexpected characters", path, first_line)
    values = values.reshape(frames, n_channels)
    finite = np.isfinite(values).all(axis=1)
    if not finite.all():
        bad = int(np.argmin(finite))
        raise MotionFormatError(
            "NaN or infinite value in frame data", path, first_line + int(rows[bad])
        )
    return values

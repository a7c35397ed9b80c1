"""The memory a run may plan to use, and the check that refuses a config needing more.

Sizes in a config that scale memory (subjects, windows, seconds x fps, image sizes) are
bounded by an estimate of the bytes they need against :func:`memory_limit`: the machine's
available memory (``MemAvailable`` of ``/proc/meminfo``, else free pages), or the limit set
in the environment variable ``AVATARSIM_MEMORY_LIMIT`` (bytes, or with a ``K``/``M``/``G``/``T``
suffix, powers of 1024). The check runs when a config is read, before anything is written.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

from avatarsim.avatar_models.config import ConfigError

MEMORY_LIMIT_ENV = "AVATARSIM_MEMORY_LIMIT"
UNITS = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}
FRAME_BYTES = 262144
"""Bytes one frame of motion costs a run or a dataset sample: the motion on its rig, the
humanoid's replay, the device streams and the per-frame reports (an upper estimate)."""


def memory_limit() -> int:
    """Bytes a run may use: ``$AVATARSIM_MEMORY_LIMIT`` if set, else the available memory."""
    text = os.environ.get(MEMORY_LIMIT_ENV, "").strip()
    if text:
        match = re.fullmatch(r"(\d+(?:\.\d+)?)\s*([KMGT]?)i?B?", text, re.IGNORECASE)
        if match is None:
            raise ConfigError(
                f"{MEMORY_LIMIT_ENV}={text!r}: give bytes, or a number with K, M, G or T"
            )
        return int(float(match[1]) * UNITS[match[2].upper()])
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


def format_bytes(n: float) -> str:
    """``n`` bytes for a message, in binary units: ``"3.2 GiB"``."""
    units = ("B", "KiB", "MiB", "GiB", "TiB", "PiB")
    k = min(int(math.log(n, 1024)), len(units) - 1) if math.isfinite(n) and n >= 1024 else 0
    return f"{n / 1024**k:.3g} {units[k]}"


def require_memory(estimate: float, what: str) -> None:
    """Raises :class:`ConfigError` when ``estimate`` bytes (for ``what``) exceed the limit."""
    limit = memory_limit()
    if not estimate <= limit:
        raise ConfigError(
            f"{what} needs about {format_bytes(estimate)} of memory, more than the "
            f"{format_bytes(limit)} available (set {MEMORY_LIMIT_ENV} to allow more)"
        )

"""Atomic file writes with ordinary permissions, and the one JSON and per-frame CSV writers.

Every writer of avatarsim writes to a temporary file beside the target and renames it into
place (:func:`atomic_file`, :func:`write_atomic`, :func:`write_json`,
:func:`write_columns_csv`), so a reader never sees half a file. ``tempfile.mkstemp`` creates
that file with mode 0600; :func:`atomic_file` gives it the mode a plain ``open()`` would have
(0666 less the user's umask, 0644 with the usual umask 022) before the rename.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def file_mode() -> int:
    """The mode ``open()`` gives a new file under the current umask."""
    return 0o666 & ~_umask()


def dir_mode() -> int:
    """The mode ``mkdir()`` gives a new folder under the current umask."""
    return 0o777 & ~_umask()


@contextmanager
def atomic_file(path: str | Path, mode: str = "wb", **open_kwargs: Any) -> Iterator[IO]:
    """Open a temporary file beside ``path`` for writing; on success it gets the umask's
    permissions and replaces ``path``; on any failure it is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, mode, **open_kwargs) as fh:
            yield fh
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` (text as UTF-8) to ``path`` atomically (:func:`atomic_file`)."""
    with atomic_file(path) as fh:
        fh.write(data.encode("utf-8") if isinstance(data, str) else data)
    return Path(path)


def sha256_file(path: str | Path) -> str:
    """Hex SHA-256 of the file at ``path``, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def json_safe(value: Any) -> Any:
    """``value`` as plain JSON data: numpy scalars and arrays as Python values, tuples as
    lists, NaN and infinities as ``None`` (strict JSON has no NaN), keys as strings."""
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating | float):
        return float(value) if math.isfinite(value) else None
    return value


def json_text(data: Any) -> str:
    """``data`` as strict JSON text (:func:`json_safe`; other objects as their ``str``),
    indented by 2, ending in a newline."""
    return json.dumps(json_safe(data), indent=2, allow_nan=False, default=str) + "\n"


def write_json(path: str | Path, data: Any) -> Path:
    """Write ``data`` to ``path`` atomically as :func:`json_text`."""
    return write_atomic(path, json_text(data))


def write_columns_csv(path: str | Path, columns: Mapping[str, Any]) -> Path:
    """Write equal-length columns (name -> ``(T,)`` values) as a CSV with a header row, one
    row per frame, atomically."""
    with atomic_file(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        writer.writerows(np.column_stack([np.asarray(c, dtype=float) for c in columns.values()]))
    return Path(path)

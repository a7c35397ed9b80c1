"""WebDataset-layout tar shards, byte-deterministic.

A shard is a plain POSIX (ustar) tar: each sample's entries ``<key>.<name>.npy`` (one per
array, ``numpy.save`` format), ``<key>.<name>`` for an encoded image (bytes whose name ends
``.jpg`` or ``.png``) then ``<key>.json``, samples in plan order, entries of a sample
sorted by name. WebDataset groups consecutive entries by the key before the first dot, so
``webdataset.WebDataset(url)`` reads these shards as they are; its sample dicts keep each
entry's suffix (``body17.npy``). Decode them with :func:`decode_entry`
(``WebDataset(url).decode(decode_entry)``): webdataset's own image decoders turn the 16-bit
depth PNGs into 8-bit or normalised floats, while this one keeps them uint16 millimetres, and
gives every entry the array :func:`read_samples` gives. Every header field that could
vary between runs is fixed (mtime 0, uid/gid 0, no user or group name, mode 0644), and the
JSON is written with sorted keys, so the same samples always give the same bytes.
"""

from __future__ import annotations

import io
import json
import tarfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.fileio import json_safe


class ShardError(AvatarsimError):
    """A shard that is not a readable tar of samples (truncated, foreign, a damaged entry)."""


SampleEntries = tuple[str, dict[str, np.ndarray | bytes], dict[str, Any]]
IMAGE_EXTENSIONS = (".jpg", ".png")


def _add(tar: tarfile.TarFile, name: str, data: bytes) -> None:
    info = tarfile.TarInfo(name)
    info.size = len(data)
    info.mtime = 0
    info.mode = 0o644
    info.uid = info.gid = 0
    info.uname = info.gname = ""
    tar.addfile(info, io.BytesIO(data))


def npy_bytes(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def json_bytes(meta: dict[str, Any]) -> bytes:
    text = json.dumps(json_safe(meta), sort_keys=True, allow_nan=False, separators=(",", ":"))
    return text.encode()


def shard_bytes(samples: list[SampleEntries]) -> bytes:
    """The tar of ``samples`` (``(key, arrays, meta)`` each), as bytes (module docstring)."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w", format=tarfile.USTAR_FORMAT) as tar:
        for key, arrays, meta in samples:
            for name in sorted(arrays):
                value = arrays[name]
                if isinstance(value, bytes):
                    _add(tar, f"{key}.{name}", value)
                else:
                    _add(tar, f"{key}.{name}.npy", npy_bytes(value))
            _add(tar, f"{key}.json", json_bytes(meta))
    return buffer.getvalue()


def decode_image(data: bytes) -> np.ndarray:
    """An encoded image entry as (H, W, 3) uint8 RGB, (H, W) uint16 (16-bit depth) or (H, W)
    uint8 (body-part labels)."""
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise ValueError("an image entry that does not decode")
    return image[..., ::-1].copy() if image.ndim == 3 else image


def decode_entry(name: str, data: bytes) -> np.ndarray | dict[str, Any] | None:
    """One entry of a sample by its name after the key (``body17.npy``,
    ``kinect_depth.0000.png``, ``json``; a leading dot, as webdataset's ``Decoder`` passes
    it, is allowed): ``.npy`` as its array, ``.jpg``/``.png`` as :func:`decode_image` (depth
    stays uint16 mm), ``json`` as a dict; ``None`` for any other name, which a webdataset
    decoder then hands to its next handler."""
    if name.endswith("json"):
        return json.loads(data)
    if name.endswith(IMAGE_EXTENSIONS):
        return decode_image(data)
    if name.endswith(".npy"):
        return np.load(io.BytesIO(data), allow_pickle=False)
    return None


def read_samples(path: Path) -> Iterator[tuple[str, dict[str, Any]]]:
    """The samples of a shard in order: ``(key, {"json": dict, name: array...})``; images
    decoded, under their entry name with its extension (``fisheye_image.{camera}.0000.jpg``).

    Raises:
        ShardError: not a tar (a truncated or foreign file), or an entry that does not
            decode (naming the shard and the entry).
    """
    try:
        tar = tarfile.open(path, mode="r:")
    except (tarfile.TarError, EOFError) as exc:
        raise ShardError(f"{path}: not a readable shard (a tar): {exc}") from None
    with tar:
        key, sample, name = None, {}, None
        try:
            for member in tar:
                name = member.name
                stem, _, ext = name.partition(".")
                if key is not None and stem != key:
                    yield key, sample
                    sample = {}
                key = stem
                data = tar.extractfile(member).read() if member.isfile() else None
                if data is None:
                    raise ValueError("not a file entry")
                value = decode_entry(ext, data)
                if value is None:
                    raise ValueError("an entry of no known kind (.npy, .json, image)")
                sample[ext.removesuffix(".npy")] = value
        except (tarfile.TarError, EOFError, OSError, ValueError) as exc:
            where = f"entry {name!r}" if name is not None else "its first entry"
            raise ShardError(f"{path}: {where} is damaged ({exc})") from None
        if key is not None:
            yield key, sample

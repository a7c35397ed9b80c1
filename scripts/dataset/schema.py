"""What a dataset's manifest and its samples hold, checked wherever they are read.

A dataset is passed between users, so what it holds is untrusted input. :func:`check_manifest`
(called by :func:`scripts.dataset.manifest.read_manifest`) and :func:`checked_samples` (every
reader of shards: ``dataset preview``, ``verify``, the torch ``ShardDataset`` behind ``train``
and ``eval controllerpose``) check against one schema, so a damaged dataset is refused the
same way everywhere: a :class:`DatasetError` naming the file and the field, before the value
is used. ``verify`` reports the same findings as problems.

Manifest (``manifest.json``, written by :func:`scripts.dataset.manifest.build_manifest`):
an object with ``schema_version`` (:data:`SCHEMA_VERSION`), ``name``, ``config`` (an
object), ``config_hash``, ``counts`` per split (non-negative ``shards``, ``samples``,
``frames``, a list of ``groups``), ``samples``, ``frames`` and ``shards``, a list of entries
each with ``name``, ``file`` (a path inside the dataset), ``split``, ``sha256`` (64 hex
digits) and non-negative ``bytes``, ``samples``, ``frames``.

Sample (``<key>.json`` and its arrays, :mod:`scripts.dataset.sample`): the JSON an object
with its ``key``, ``split``, ``group``, ``frames`` (``T``), ``fps``, ``channels`` (an object)
and ``arrays`` (the array entries, each present); every array numeric or boolean, and the
known ones of the shapes in :data:`ARRAY_DIMS` (letters are sizes that must agree within the
sample: ``T`` the frames, ``Tv``/``Tc``/``Tk`` the VR, camera and Kinect frames, ``D``
devices, ``C`` cameras, ``V`` views, ``J`` Kinect joints, ``nq`` the humanoid's qpos).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.body17_angles import N_DOF
from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.scripts.dataset.config import SPLITS
from avatarsim.scripts.dataset.shards import read_samples

SCHEMA_VERSION = 1
"""The manifest's ``schema_version`` this avatarsim writes and reads."""
J17 = len(BODY17)
ARRAY_DIMS: dict[str, tuple[str | int, ...]] = {
    "body17": ("T", J17, 3),
    "body17_angles": ("T", N_DOF),
    "qpos": ("T", "nq"),
    "contact": ("T", 2),
    "penetration_m": ("T",),
    "skate_m_s": ("T", 2),
    "vr_time": ("Tv",),
    "vr_pos": ("Tv", "D", 3),
    "vr_quat": ("Tv", "D", 4),
    "vr_valid": ("Tv", "D"),
    "fisheye_uv": ("Tc", "C", J17, 2),
    "fisheye_conf": ("Tc", "C", J17),
    "fisheye_detected": ("Tc", "C", J17),
    "fisheye_uv_projected": ("Tc", "C", J17, 2),
    "fisheye_in_view": ("Tc", "C", J17),
    "fisheye_lens_covered": ("Tc", "C"),
    "fisheye_w2c": ("Tc", "C", 4, 4),
    "fisheye_view_uv": ("Tc", "V", J17, 2),
    "fisheye_view_conf": ("Tc", "V", J17),
    "fisheye_view_detected": ("Tc", "V", J17),
    "kinect_pos": ("Tk", "J", 3),
    "kinect_quat": ("Tk", "J", 4),
    "kinect_state": ("Tk", "J"),
}
NUMERIC_KINDS = "biuf"  # bool, signed and unsigned integers, floats
SHA256 = re.compile(r"[0-9a-f]{64}")
MIN_SAMPLE_BYTES = 1024
"""A sample takes at least one tar entry: a 512-byte header and a 512-byte block."""


class DatasetError(AvatarsimError):
    """A dataset folder that is not what a command needs (missing, foreign, inconsistent,
    damaged)."""


def _count(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _positive(value: Any) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and value > 0
    )


def _inside(file: Any) -> bool:
    """A relative path that stays inside the dataset folder."""
    if not isinstance(file, str) or not file or "\\" in file:
        return False
    parts = PurePosixPath(file).parts
    return not PurePosixPath(file).is_absolute() and ".." not in parts


def _require(ok: bool, where: str | Path, field: str, value: Any, want: str) -> None:
    if not ok:
        shown = repr(value) if len(repr(value)) <= 60 else f"a {type(value).__name__}"
        raise DatasetError(f"{where}: {field} is {shown}, expected {want}")


def check_manifest(manifest: Any, path: Path) -> dict[str, Any]:
    """``manifest`` (parsed from ``path``) when it has the schema's fields and types (module
    docstring); returns it.

    Raises:
        DatasetError: naming ``path`` and the first wrong field.
    """
    _require(isinstance(manifest, dict), path, "the manifest", manifest, "an object")
    version = manifest.get("schema_version")
    if version != SCHEMA_VERSION:
        raise DatasetError(
            f"{path}: manifest schema {version!r}, this avatarsim reads {SCHEMA_VERSION}"
        )
    for field in ("name", "config_hash"):
        _require(isinstance(manifest.get(field), str), path, field, manifest.get(field), "text")
    _require(isinstance(manifest.get("config"), dict), path, "config", None, "an object")
    for field in ("samples", "frames"):
        _require(_count(manifest.get(field)), path, field, manifest.get(field), "a count")
    counts = manifest.get("counts")
    _require(isinstance(counts, dict), path, "counts", counts, "an object by split")
    for split in SPLITS:
        entry = counts.get(split)
        _require(isinstance(entry, dict), path, f"counts.{split}", entry, "an object")
        for field in ("shards", "samples", "frames"):
            value = entry.get(field)
            _require(_count(value), path, f"counts.{split}.{field}", value, "a count")
        groups = entry.get("groups")
        _require(isinstance(groups, list), path, f"counts.{split}.groups", groups, "a list")
    shards = manifest.get("shards")
    _require(isinstance(shards, list), path, "shards", shards, "a list of shard entries")
    for k, entry in enumerate(shards):
        where = f"shards[{k}]"
        _require(isinstance(entry, dict), path, where, entry, "an object")
        _require(
            isinstance(entry.get("name"), str), path, f"{where}.name", entry.get("name"), "text"
        )
        file = entry.get("file")
        _require(_inside(file), path, f"{where}.file", file, "a path inside the dataset")
        split = entry.get("split")
        _require(split in SPLITS, path, f"{where}.split", split, f"one of {', '.join(SPLITS)}")
        sha = entry.get("sha256")
        ok = isinstance(sha, str) and SHA256.fullmatch(sha) is not None
        _require(ok, path, f"{where}.sha256", sha, "64 hex digits")
        for field in ("bytes", "samples", "frames"):
            value = entry.get(field)
            _require(_count(value), path, f"{where}.{field}", value, "a count")
        samples = entry["samples"]
        room = entry["bytes"] // MIN_SAMPLE_BYTES
        _require(samples <= room, path, f"{where}.samples", samples, f"at most {room} in its bytes")
    return manifest


def check_sample(key: str, sample: dict[str, Any], path: Path) -> dict[str, Any]:
    """``sample`` (read from shard ``path``) when its JSON and arrays have the schema's
    fields, types and shapes (module docstring); returns it.

    Raises:
        DatasetError: naming ``path``, the sample and the first wrong field.
    """
    where = f"{path}: sample {key}"
    meta = sample.get("json")
    _require(isinstance(meta, dict), where, "its JSON", meta, "an object")
    _require(meta.get("key") == key, where, "key", meta.get("key"), repr(key))
    _require(meta.get("split") in SPLITS, where, "split", meta.get("split"), "a split")
    _require(isinstance(meta.get("group"), str), where, "group", meta.get("group"), "text")
    frames = meta.get("frames")
    _require(_count(frames) and frames > 0, where, "frames", frames, "a positive count")
    _require(_positive(meta.get("fps")), where, "fps", meta.get("fps"), "a positive number")
    _require(isinstance(meta.get("channels"), dict), where, "channels", None, "an object")
    listed = meta.get("arrays")
    ok = isinstance(listed, list) and all(isinstance(n, str) for n in listed)
    _require(ok, where, "arrays", listed, "a list of entry names")
    missing = [n for n in listed if n not in sample]
    _require(not missing, where, "arrays", missing[:3], "entries present in the shard")
    sizes: dict[str, int] = {"T": frames}
    for name, value in sample.items():
        if name == "json" or not isinstance(value, np.ndarray):
            continue
        kind = value.dtype.kind
        _require(kind in NUMERIC_KINDS, where, name, f"of dtype {value.dtype}", "numbers")
        dims = ARRAY_DIMS.get(name)
        if dims is None:
            continue
        ok = value.ndim == len(dims)
        for size, dim in zip(value.shape, dims, strict=False):
            expected = sizes.setdefault(dim, size) if isinstance(dim, str) else dim
            ok = ok and size == expected
        _require(ok, where, f"{name} shape", value.shape, f"({', '.join(map(str, dims))})")
    return sample


def checked_samples(
    path: Path, expected: int | None = None
) -> Iterator[tuple[str, dict[str, Any]]]:
    """:func:`scripts.dataset.shards.read_samples`, each sample checked (:func:`check_sample`),
    and (with ``expected``, the manifest's count) as many as the manifest says: a shard cut
    at a sample's end reads as a shorter tar.

    Raises:
        ShardError: an unreadable shard. DatasetError: a sample off the schema, or another
            number of samples than ``expected``.
    """
    count = 0
    for key, sample in read_samples(path):
        count += 1
        if expected is not None and count > expected:
            break
        yield key, check_sample(key, sample, path)
    if expected is not None and count != expected:
        held = f"more than {expected}" if count > expected else str(count)
        raise DatasetError(f"{path}: holds {held} samples, its manifest entry says {expected}")

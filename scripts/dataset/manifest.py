"""The files that describe a dataset folder, besides its shards.

Layout of ``DIR``::

    dataset.json        written first: schema version, the config and its hash (the identity
                        a resumed run must match)
    shards/{split}-{k:06d}.tar    the shards (:mod:`.shards`)
    shards/{split}-{k:06d}.json   each shard's sidecar, written after it: sha256, bytes,
                        samples, frames, groups; a shard counts as done only when its tar's
                        sha256 matches its sidecar
    manifest.json       written last, from the sidecars: schema version, the config and its
                        hash, counts per split, every shard's sha256

Every file is written atomically (a temporary name, then ``os.replace``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from avatarsim.avatar_models.fileio import sha256_file, write_json
from avatarsim.scripts.dataset.config import SPLITS, DatasetConfig, config_hash
from avatarsim.scripts.dataset.schema import SCHEMA_VERSION, DatasetError, check_manifest

STATE_FILE = "dataset.json"
MANIFEST_FILE = "manifest.json"
SHARD_DIR = "shards"


def shard_path(root: Path, name: str) -> Path:
    return root / SHARD_DIR / f"{name}.tar"


def sidecar_path(root: Path, name: str) -> Path:
    return root / SHARD_DIR / f"{name}.json"


def read_json(path: Path, what: str) -> dict[str, Any]:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DatasetError(f"{path}: no {what}") from None
    except (OSError, ValueError) as exc:
        raise DatasetError(f"{path}: unreadable {what}: {exc}") from None


def state(config: DatasetConfig) -> dict[str, Any]:
    """The content of ``dataset.json`` for ``config``."""
    return {
        "schema_version": SCHEMA_VERSION,
        "config": config.as_dict(),
        "config_hash": config_hash(config),
    }


def done_sidecar(root: Path, name: str) -> dict[str, Any] | None:
    """The sidecar of shard ``name`` when the shard is complete (its tar's sha256 matches),
    else None."""
    tar, sidecar = shard_path(root, name), sidecar_path(root, name)
    if not (tar.is_file() and sidecar.is_file()):
        return None
    try:
        recorded = json.loads(sidecar.read_text(encoding="utf-8"))
    except ValueError:
        return None
    if not isinstance(recorded, dict):
        return None
    return recorded if recorded.get("sha256") == sha256_file(tar) else None


def write_sidecar(root: Path, sidecar: dict[str, Any]) -> None:
    write_json(sidecar_path(root, sidecar["name"]), sidecar)


def build_manifest(config: DatasetConfig, sidecars: list[dict[str, Any]]) -> dict[str, Any]:
    """The manifest from the sidecars of every shard (in plan order)."""
    counts = {}
    for split in SPLITS:
        mine = [s for s in sidecars if s["split"] == split]
        counts[split] = {
            "shards": len(mine),
            "samples": sum(s["samples"] for s in mine),
            "frames": sum(s["frames"] for s in mine),
            "groups": sorted({g for s in mine for g in s["groups"]}),
        }
    return {
        **state(config),
        "name": config.name,
        "counts": counts,
        "samples": sum(c["samples"] for c in counts.values()),
        "frames": sum(c["frames"] for c in counts.values()),
        "shards": [
            {k: s[k] for k in ("name", "file", "split", "sha256", "bytes", "samples", "frames")}
            for s in sidecars
        ],
    }


def write_manifest(root: Path, manifest: dict[str, Any]) -> None:
    write_json(root / MANIFEST_FILE, manifest)


def read_manifest(root: Path) -> dict[str, Any]:
    """The manifest of the dataset in ``root``, checked against the schema
    (:func:`scripts.dataset.schema.check_manifest`).

    Raises:
        DatasetError: no dataset there, its generation has not finished, or a field of the
            manifest is missing or of the wrong type (naming the file and the field).
    """
    if not (root / MANIFEST_FILE).is_file() and (root / STATE_FILE).is_file():
        raise DatasetError(f"{root}: generation has not finished (run generate again to resume)")
    manifest = read_json(root / MANIFEST_FILE, "dataset manifest")
    return check_manifest(manifest, root / MANIFEST_FILE)

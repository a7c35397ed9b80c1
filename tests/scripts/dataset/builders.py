"""Tiny dataset configs for the dataset tests: a few 1-second samples, a shard or two each."""

from __future__ import annotations

from pathlib import Path

import tomli_w

TINY = {
    "name": "tiny",
    "seed": 3,
    "samples_per_shard": 2,
    "window": {"seconds": 1.0, "fps": 30.0},
    "splits": {"train": 0.6, "val": 0.2, "test": 0.2},
    "sources": [{"kind": "builtin", "activities": ["wave", "squat"], "subjects": 5}],
    "devices": [{"name": "vrk", "kinect": "kinect-v2", "vr_noise": "realistic"}],
}


def write_config(path: Path, **changes) -> Path:
    """``TINY`` with top-level ``changes``, written as TOML to ``path``."""
    path.write_text(tomli_w.dumps({**TINY, **changes}))
    return path


def tree_bytes(root: Path) -> dict[str, bytes]:
    """Every file below ``root`` by relative path, with its bytes."""
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }

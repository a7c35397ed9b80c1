"""Single output files named by the user (``--json``, ``dataset preview --out``, ``convert
OUT``, ``--baseline`` with ``--update-baseline``): written atomically, never a user's file
replaced.

A command writes such a file with :func:`write_output` (a temporary file beside it, then a
rename: :func:`avatar_models.fileio.write_atomic`) and records the sha256 of what it wrote in
:data:`REGISTRY`, a small JSON file in the same folder (``{"files": {name: sha256}}``). An
existing file may be replaced only when the registry says avatarsim wrote it and it is
unchanged since (its sha256 still matches), so a rerun replaces its own output while an edited
file, or anyone else's, is refused before any work starts (:func:`check_replaceable`), as
:func:`scripts.results.atomic_dir` refuses a folder it did not write.
"""

from __future__ import annotations

import json
from pathlib import Path

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.fileio import sha256_file, write_atomic, write_json

REGISTRY = ".avatarsim-files.json"


def _registry(folder: Path) -> dict[str, str]:
    """Name -> sha256 of the files avatarsim wrote in ``folder`` (empty when none or
    unreadable: then nothing there counts as ours)."""
    try:
        files = json.loads((folder / REGISTRY).read_text(encoding="utf-8"))["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return {}
    if not isinstance(files, dict):
        return {}
    return {str(k): v for k, v in files.items() if isinstance(v, str)}


def written_by_us(path: Path) -> bool:
    """``path`` is a file avatarsim wrote and nobody changed since."""
    path = Path(path)
    recorded = _registry(path.parent).get(path.name)
    return recorded is not None and path.is_file() and sha256_file(path) == recorded


def check_replaceable(path: Path | None, option: str) -> None:
    """Before any work: ``path`` does not exist, or is a file avatarsim wrote and nobody
    changed since. Raises :class:`AvatarsimError` otherwise; writes nothing."""
    if path is None:
        return
    path = Path(path)
    if path.name == REGISTRY:
        raise AvatarsimError(f"{option} {path} is avatarsim's record of its files; choose another")
    if (path.exists() or path.is_symlink()) and not (path.is_file() and written_by_us(path)):
        raise AvatarsimError(
            f"{option} {path} already exists and was not written by avatarsim (or was changed "
            "since); delete it or choose another path"
        )


def record_output(path: Path) -> Path:
    """Record the file ``path`` (just written by avatarsim) as ours; returns ``path``."""
    path = Path(path)
    files = _registry(path.parent)
    files[path.name] = sha256_file(path)
    write_json(path.parent / REGISTRY, {"files": dict(sorted(files.items()))})
    return path


def write_output(path: Path, data: bytes | str, option: str) -> Path:
    """Write ``data`` to the user's output file ``path`` (module docstring): refused (checked
    again, as it may have appeared meanwhile) unless replaceable, written atomically, recorded."""
    check_replaceable(path, option)
    return record_output(write_atomic(path, data))

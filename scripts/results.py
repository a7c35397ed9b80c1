"""Run results: the contract's JSON and JUnit XML for CI, both written atomically."""

from __future__ import annotations

import json
import os
import platform
import shutil
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.avatar_models.fileio import dir_mode, write_json
from avatarsim.scripts.output_file import check_replaceable
from avatarsim.scripts.scenario import Threshold


@dataclass(frozen=True)
class ThresholdResult:
    """One scenario threshold applied to one run metric (a row of ``checks`` in
    ``results.json`` and a JUnit testcase); not a physics check's finding
    (:class:`sim.checks.CheckResult`). ``expected_fail`` (the scenario's ``expect_fail``)
    turns the verdict round: it passes when the threshold is NOT met (a detector proven)."""

    name: str
    value: float
    threshold: Threshold
    expected_fail: bool = False

    @property
    def passed(self) -> bool:
        return self.threshold.passes(self.value) != self.expected_fail

    def failure_message(self) -> str:
        """Why a check that did not pass failed (empty when it passed)."""
        if self.passed:
            return ""
        if self.expected_fail:
            return f"{self.value:.4g} is {self.threshold.describe()}, but expected to fail"
        return f"{self.value:.4g} not {self.threshold.describe()}"

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "value": self.value,
            "threshold": self.threshold.max
            if self.threshold.min is None
            else self.threshold.describe(),
            "passed": self.passed,
            **({"expected_fail": True} if self.expected_fail else {}),
        }


def versions() -> dict[str, str]:
    """Versions of the things that can change results."""
    out = {"python": platform.python_version()}
    for dist in ("avatarsim", "numpy", "scipy", "mujoco", "torch"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "absent"
    return out


OUTPUT_MARKER = ".avatarsim-output.json"


def _nearest_existing(path: Path) -> Path:
    """``path`` or its closest ancestor that exists."""
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def _probe_writable(folder: Path, option: str, path: Path) -> None:
    """Create and remove a temporary folder in ``folder``: the only test of writability that
    also holds for root, read-only mounts and full disks."""
    try:
        probe = tempfile.mkdtemp(dir=folder, prefix=".avatarsim-probe-")
    except OSError as exc:
        raise AvatarsimError(
            f"{option} {path}: cannot write in {folder} ({exc.strerror or exc})"
        ) from None
    os.rmdir(probe)


def _check_ancestors(path: Path, option: str) -> Path:
    """The nearest existing ancestor of ``path``; an error if it is not a folder."""
    existing = _nearest_existing(path.parent)
    if not existing.is_dir():
        raise AvatarsimError(f"{option} {path}: {existing} is a file, not a folder")
    return existing


def check_output_file(path: Path | None, option: str, replaced: bool = False) -> None:
    """Before any work: ``path`` can be written as a file (not a folder, not below a file,
    in a writable folder) and, unless the command ``replaced`` it on purpose, is not a file
    avatarsim did not write (:func:`scripts.output_file.check_replaceable`). Writes nothing."""
    if path is None:
        return
    path = Path(path)
    if path.is_dir():
        raise AvatarsimError(f"{option} {path} is a folder; give a file name")
    if str(path).endswith(os.sep):
        raise AvatarsimError(f"{option} {path} names a folder; give a file name")
    if not replaced:
        check_replaceable(path, option)
    _probe_writable(_check_ancestors(path, option), option, path)


def check_output_dir(path: Path | None, option: str, owner: str | None = None) -> None:
    """Before any work: ``path`` can be used as an output folder (not a file, not below a
    file, writable). With ``owner`` (a command that replaces its folder whole, see
    :func:`atomic_dir`), an existing non-empty folder must be a previous output of that
    command holding only files it wrote. Writes nothing."""
    if path is None:
        return
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise AvatarsimError(f"{option} {path} is a file, not a folder")
    existing = _check_ancestors(path, option)
    # A folder written into must be writable; one replaced whole, its parent.
    _probe_writable(path if owner is None and path.is_dir() else existing, option, path)
    if owner is not None and path.is_dir():
        _check_owned(path, option, owner)


# More files than any output of ours holds: a folder with more is nobody's output of ours,
# and is not walked further (``--out /`` answers at once).
_MAX_FILES = 10_000


def _files_in(folder: Path) -> set[str]:
    """Entries below ``folder`` (relative paths), at most :data:`_MAX_FILES` + 1 of them:
    files, links to folders and empty folders (none of which an output of ours has)."""
    found: set[str] = set()
    for root, dirs, files in os.walk(folder):
        here = Path(root)
        links = [d for d in dirs if (here / d).is_symlink()]
        empty = [] if files or dirs or here == Path(folder) else [""]
        for name in [*files, *links, *empty]:
            found.add(str((here / name).relative_to(folder)))
            if len(found) > _MAX_FILES:
                return found
    return found


def _earlier_output(folder: Path, owner: str, present: set[str]) -> set[str]:
    """The files of an output written before :data:`OUTPUT_MARKER` existed: the three files
    of ``control`` (then called ``track``, its files ``tracking.*``), or a run's folder
    (``results.json`` naming its outputs, whose folders hold the rest). Empty when ``folder``
    is not such an output."""
    try:
        if owner == "control":
            names = {"tracking.csv", "tracking.json", "tracking.png"}
            summary = json.loads((folder / "tracking.json").read_text(encoding="utf-8"))
            return present if present <= names and "mode" in summary else set()
        if owner == "run":
            results = json.loads((folder / "results.json").read_text(encoding="utf-8"))
            listed = {str(v) for v in results["outputs"].values()} | {"results.json"}
            if not {"scenario", "versions"} <= set(results) or "junit.xml" not in listed:
                return set()
            tops = {Path(v).parts[0] for v in listed if len(Path(v).parts) > 1}
            return {f for f in present if f in listed or Path(f).parts[0] in tops}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        pass
    return set()


def _check_owned(folder: Path, option: str, owner: str) -> None:
    """``folder`` is empty or a previous output of ``owner`` with nothing else in it."""
    present = _files_in(folder)
    if not present:
        return
    if len(present) > _MAX_FILES:
        raise AvatarsimError(
            f"{option} {folder} holds more than {_MAX_FILES} files, more than any output of "
            f"`avatarsim {owner}`; it would be replaced whole, so choose a new or empty folder"
        )
    try:
        marker = json.loads((folder / OUTPUT_MARKER).read_text(encoding="utf-8"))
        command, files = str(marker["command"]), set(marker["files"])
    except (OSError, ValueError, KeyError, TypeError):
        command, files = None, _earlier_output(folder, owner, present)
        command = owner if files else None
    ours = files | {OUTPUT_MARKER} if command == owner else set()
    # The user's own files first, hidden ones (a marker) last.
    foreign = sorted(present - ours, key=lambda f: (Path(f).name.startswith("."), f))
    if foreign:
        whose = (
            f" (it is an output of `avatarsim {command}`)" if command not in (None, owner) else ""
        )
        raise AvatarsimError(
            f"{option} {folder} holds files not written by `avatarsim {owner}`{whose}, e.g. "
            f"{foreign[0]!r}; it would be replaced whole, so choose a new or empty folder"
        )


@contextmanager
def atomic_dir(final_dir: Path, owner: str) -> Iterator[Path]:
    """A hidden sibling folder to write into; it replaces ``final_dir`` only when the block
    completes, so a failed run never leaves half its outputs behind (nor the hidden folder).

    ``final_dir`` is replaced whole, so it is only replaced when it is empty or a previous
    output of ``owner`` (recorded in :data:`OUTPUT_MARKER` with the files written) holding
    nothing else; otherwise :class:`AvatarsimError`, before anything is written. A user's file
    is never deleted."""
    final_dir = Path(os.path.abspath(final_dir))  # "." or "a/..": the parent is real
    check_output_dir(final_dir, "--out", owner)
    final_dir.parent.mkdir(parents=True, exist_ok=True)
    out_dir = Path(tempfile.mkdtemp(dir=final_dir.parent, prefix=f".{final_dir.name}.partial-"))
    try:
        yield out_dir
        write_json(out_dir / OUTPUT_MARKER, {"command": owner, "files": sorted(_files_in(out_dir))})
        os.chmod(out_dir, dir_mode())
        if final_dir.exists():
            _check_owned(final_dir, "--out", owner)  # again: it may have changed meanwhile
            old = Path(tempfile.mkdtemp(dir=final_dir.parent, prefix=f".{final_dir.name}.old-"))
            try:
                os.replace(final_dir, old / "x")
                try:
                    os.replace(out_dir, final_dir)
                except BaseException:
                    os.replace(old / "x", final_dir)  # the earlier output stays as it was
                    raise
            finally:
                shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(out_dir, final_dir)
    except BaseException:
        shutil.rmtree(out_dir, ignore_errors=True)
        raise


def junit_xml(suite: str, checks: list[ThresholdResult], time_s: float = 0.0) -> str:
    """One testcase per check; a failed check carries a <failure> with value and threshold."""
    failures = sum(not c.passed for c in checks)
    root = ET.Element(
        "testsuite",
        name=suite,
        tests=str(len(checks)),
        failures=str(failures),
        time=f"{time_s:.3f}",
    )
    for c in checks:
        case = ET.SubElement(root, "testcase", classname=f"avatarsim.{suite}", name=c.name)
        if not c.passed:
            failure = ET.SubElement(case, "failure", message=c.failure_message())
            failure.text = f"{c.name} = {c.value!r}, threshold {c.threshold.describe()}"
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"

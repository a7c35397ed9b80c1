"""Run results: the contract's JSON and JUnit XML for CI, both written atomically."""

from __future__ import annotations

import json
import math
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

import numpy as np

from scripts.scenario import Threshold


@dataclass(frozen=True)
class CheckResult:
    name: str
    value: float
    threshold: Threshold

    @property
    def passed(self) -> bool:
        return self.threshold.passes(self.value)

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "value": self.value,
            "threshold": self.threshold.max
            if self.threshold.min is None
            else self.threshold.describe(),
            "passed": self.passed,
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


@contextmanager
def atomic_dir(final_dir: Path) -> Iterator[Path]:
    """A hidden sibling folder to write into; it replaces ``final_dir`` only when the block
    completes, so a failed run never leaves half its outputs behind."""
    final_dir = Path(final_dir)
    final_dir.parent.mkdir(parents=True, exist_ok=True)
    out_dir = Path(tempfile.mkdtemp(dir=final_dir.parent, prefix=f".{final_dir.name}.partial-"))
    try:
        yield out_dir
    except BaseException:
        shutil.rmtree(out_dir, ignore_errors=True)
        raise
    if final_dir.exists():
        shutil.rmtree(final_dir)
    os.replace(out_dir, final_dir)
    final_dir.chmod(0o755)


def write_atomic(path: Path, data: bytes | str) -> Path:
    """Write to a temp file in the same folder, then rename: readers never see half a file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.chmod(tmp, 0o644)  # mkstemp makes it private; results are for sharing
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _plain(value: Any) -> Any:
    """JSON-safe: numpy scalars and arrays as Python values, NaN/inf as null (strict JSON)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating | float):
        return float(value) if math.isfinite(value) else None
    return value


def write_json(path: Path, payload: dict[str, Any]) -> Path:
    text = json.dumps(_plain(payload), indent=2, allow_nan=False, default=str)
    return write_atomic(path, text + "\n")


def junit_xml(suite: str, checks: list[CheckResult], time_s: float = 0.0) -> str:
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
            failure = ET.SubElement(
                case, "failure", message=f"{c.value:.4g} not {c.threshold.describe()}"
            )
            failure.text = f"{c.name} = {c.value!r}, threshold {c.threshold.describe()}"
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"

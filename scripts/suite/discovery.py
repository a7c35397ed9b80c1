"""Which scenarios a suite runs: files and folders -> scenarios, every one checked before any
runs (a bad file, two scenarios with one name, a missing motion file), then ``-k`` selection.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from avatarsim.avatar_models.mocap_dir import MOCAP_ENV, is_mocap_source
from avatarsim.scripts.pipeline import validate
from avatarsim.scripts.scenario import Scenario, ScenarioError, load_scenario

# A scenario's name is its output folder's name; the suite's own files sit beside them.
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")
SUITE_FILES = ("junit.xml", "results.json", "index.html")


@dataclass(frozen=True)
class SuiteEntry:
    """A checked scenario; ``skip_reason`` when it cannot run here (its real mocap absent)."""

    scenario: Scenario
    skip_reason: str | None = None

    @property
    def name(self) -> str:
        return self.scenario.name


def scenario_files(paths: Sequence[Path]) -> list[Path]:
    """``*.toml`` files of ``paths`` (folders searched recursively, sorted), each once."""
    files: list[Path] = []
    for path in map(Path, paths):
        if path.is_dir():
            found = sorted(path.rglob("*.toml"))
            if not found:
                raise ScenarioError(f"folder {path} holds no scenario (*.toml) file")
            files += found
        elif path.is_file():
            files.append(path)
        else:
            raise ScenarioError(f"scenario path {path} does not exist")
    unique = {f.resolve(): f for f in reversed(files)}
    return [f for f in files if unique.get(f.resolve()) is f]


def check_scenario(path: Path, seed: int | None = None) -> SuiteEntry:
    """The scenario of ``path``, validated as ``run`` would before running it."""
    scenario = load_scenario(path)
    if seed is not None:
        scenario = dataclasses.replace(scenario, seed=seed)
    if not NAME.fullmatch(scenario.name) or scenario.name in SUITE_FILES:
        raise ScenarioError(
            f"name {scenario.name!r} cannot name an output folder (letters, digits, '.', '_', "
            f"'-'; not {', '.join(SUITE_FILES)})"
        )
    validate(scenario)
    source = scenario.motion.source
    if source == "builtin" or Path(source).is_file():
        return SuiteEntry(scenario)
    if scenario.motion.skip_if_absent:
        if is_mocap_source(source):
            return SuiteEntry(scenario, f"{source}: no mocap folder set ({MOCAP_ENV} or --mocap)")
        return SuiteEntry(scenario, f"motion file {source} is absent (motion.skip_if_absent)")
    raise ScenarioError(f"motion file {source} does not exist")


def selected(entries: list[SuiteEntry], pattern: str | None) -> list[SuiteEntry]:
    """Entries whose name contains ``pattern``, or matches it as a glob (``*``, ``?``, ``[]``)."""
    if pattern is None:
        return entries
    chosen = [e for e in entries if pattern in e.name or fnmatch.fnmatchcase(e.name, pattern)]
    if not chosen:
        raise ScenarioError(
            f"-k {pattern!r} selects no scenario; names: {', '.join(e.name for e in entries)}"
        )
    return chosen


def load_suite(
    paths: Sequence[Path], pattern: str | None = None, seed: int | None = None
) -> list[SuiteEntry]:
    """Every scenario of ``paths`` checked (all problems of all files in one message), then
    the ``pattern`` selection. Raises :class:`ScenarioError` before anything has run."""
    entries, problems = [], []
    for path in scenario_files(paths):
        try:
            entries.append(check_scenario(path, seed))
        except ScenarioError as exc:
            text = str(exc)
            problems.append(text if str(path) in text else f"{path}: {text}")
    if problems:
        raise ScenarioError(f"{len(problems)} bad scenario file(s): " + "; ".join(problems))
    first: dict[str, Scenario] = {}
    for entry in entries:
        earlier = first.setdefault(entry.name, entry.scenario)
        if earlier is not entry.scenario:
            raise ScenarioError(
                f"two scenarios are named {entry.name!r} ({earlier.path} and "
                f"{entry.scenario.path}); names must be unique in a suite (they name folders)"
            )
    return selected(entries, pattern)

"""Regression against a stored baseline: which metrics got worse beyond their tolerance.

A baseline is a suite's ``results.json`` (or one scenario's). Metrics are compared only for a
scenario whose seed and :func:`~scripts.scenario_identity.scenario_hash` match the baseline's;
a baseline from another scenario version is refused before anything runs. Tolerances come
from the scenario's ``[regression]`` table (absolute, in the metric's unit) or from defaults
by metric kind (:data:`DEFAULT_TOLERANCES`). Timings are never compared: they measure the
machine, not the method.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avatarsim.scripts.scenario import Scenario, ScenarioError
from avatarsim.scripts.scenario_identity import scenario_hash


@dataclass(frozen=True)
class Tolerance:
    """Allowed worsening: ``max(absolute, relative * |baseline|)``, in the metric's unit."""

    absolute: float
    relative: float = 0.0

    def of(self, baseline: float) -> float:
        return max(self.absolute, self.relative * abs(baseline))


# Accuracy: 0.5 cm is well under the ~1 cm the methods' errors move between seeds (the
# methods/ suite's measurements), above float noise. Rates and fractions: 2 points.
# Physics values swing with contact events: 10 %, at least 0.5 of the unit.
DEFAULT_TOLERANCES = {
    "accuracy": Tolerance(0.5),
    "rate": Tolerance(0.02),
    "physics": Tolerance(0.5, 0.10),
}
TIMINGS = ("_fps_rendered", "_x_real_time")  # they measure the machine
HIGHER_IS_BETTER = ("hand_corr", "valid_frac", "upright_s")


def metric_kind(name: str) -> str | None:
    """``accuracy``, ``rate`` or ``physics``; None for metrics never compared."""
    if name == "frames" or name.endswith(TIMINGS):
        return None
    if "err_cm" in name or "error_mm" in name or "residual_cm" in name:
        return "accuracy"
    if "corr" in name or name.endswith("_frac") or name.endswith("_fell"):
        return "rate"
    return "physics"


@dataclass(frozen=True)
class Comparison:
    """One metric against its baseline; ``worse_by`` > 0 means worse (in its unit)."""

    metric: str
    baseline: float
    value: float | None
    tolerance: float

    @property
    def worse_by(self) -> float:
        if self.value is None:  # NaN (written as null): nothing is worse than no value
            return float("inf")
        sign = -1.0 if any(k in self.metric for k in HIGHER_IS_BETTER) else 1.0
        return sign * (self.value - self.baseline)

    @property
    def regressed(self) -> bool:
        return self.worse_by > self.tolerance

    @property
    def improved(self) -> bool:
        return -self.worse_by > self.tolerance

    def to_json(self) -> dict[str, Any]:
        return {
            "metric": self.metric,
            "baseline": self.baseline,
            "value": self.value,
            "tolerance": self.tolerance,
            "regressed": self.regressed,
            "improved": self.improved,
        }


def compare(
    baseline: dict[str, float | None],
    metrics: dict[str, float | None],
    tolerances: dict[str, float],
) -> list[Comparison]:
    """Every comparable metric present in both, sorted by name; ``tolerances`` (absolute)
    override the defaults by kind."""
    out = []
    for name in sorted(set(baseline) & set(metrics)):
        kind, base = metric_kind(name), baseline[name]
        if kind is None or base is None:
            continue
        tol = tolerances.get(name)
        tol = DEFAULT_TOLERANCES[kind].of(base) if tol is None else tol
        out.append(Comparison(name, base, metrics[name], tol))
    return out


@dataclass(frozen=True)
class BaselineEntry:
    seed: int
    scenario_hash: str
    metrics: dict[str, float | None]


def baseline_file(path: Path) -> Path:
    """The JSON file of ``--baseline PATH``: PATH itself, or ``PATH/results.json``."""
    path = Path(path)
    return path if path.suffix == ".json" and not path.is_dir() else path / "results.json"


def _metric(value: Any) -> bool:
    """A stored metric: a finite number, or null (NaN as written by ``write_json``)."""
    return value is None or (
        isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    )


def _entry(results: Any, file: Path) -> tuple[str, BaselineEntry] | None:
    """One scenario's baseline from its record in ``file`` (None for a scenario that stored
    no metrics, e.g. one that errored), every field checked before anything runs.

    Raises:
        ScenarioError: naming ``file`` and the field that is missing or of the wrong type.
    """

    def bad(field: str, why: str) -> ScenarioError:
        return ScenarioError(
            f"--baseline {file}: {field} {why}; it is not the results.json of an avatarsim "
            "run (rerun with --update-baseline)"
        )

    if not isinstance(results, dict):
        raise bad("a scenario record", f"is {type(results).__name__}, not an object")
    name = results.get("name", results.get("scenario"))
    if not isinstance(name, str):
        raise bad("'name' (or 'scenario')", f"is {name!r}, not a scenario name")
    metrics = results.get("metrics")
    if metrics is None:
        return None
    if not isinstance(metrics, dict):
        raise bad(f"{name}: 'metrics'", f"is {type(metrics).__name__}, not an object")
    wrong = next((k for k, v in metrics.items() if not _metric(v)), None)
    if wrong is not None:
        raise bad(f"{name}: metrics[{wrong!r}]", f"is {metrics[wrong]!r}, not a finite number")
    seeds = results.get("seeds")
    seed = seeds.get("scenario") if isinstance(seeds, dict) else None
    if not isinstance(seed, int) or isinstance(seed, bool):
        raise bad(f"{name}: 'seeds.scenario'", f"is {seed!r}, not an integer")
    chash = results.get("scenario_hash")
    if not isinstance(chash, str):
        raise bad(f"{name}: 'scenario_hash'", f"is {chash!r}, not a hash")
    return name, BaselineEntry(seed, chash, metrics)


def load_baseline(path: Path) -> dict[str, BaselineEntry]:
    """Scenario name -> its baseline, from a suite's or one scenario's ``results.json``.

    Raises:
        ScenarioError: unreadable, not JSON, or a field of the wrong type (:func:`_entry`).
    """
    file = baseline_file(path)
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ScenarioError(f"--baseline {file}: cannot read ({exc.strerror or exc})") from None
    except ValueError as exc:
        raise ScenarioError(
            f"--baseline {file} is not JSON ({exc}); give the results.json of an avatarsim run"
        ) from None
    runs = data.get("scenarios", [data]) if isinstance(data, dict) else data
    if not isinstance(runs, list):
        raise ScenarioError(
            f"--baseline {file}: 'scenarios' is {type(runs).__name__}, not a list of records"
        )
    entries = (_entry(r, file) for r in runs)
    return dict(e for e in entries if e is not None)


def check_baseline(
    baseline: dict[str, BaselineEntry], scenarios: Iterable[Scenario], where: Path
) -> None:
    """Refuse a baseline stored for another version or seed of any of ``scenarios``."""
    for sc in scenarios:
        stored = baseline.get(sc.name)
        if stored is None:
            continue
        if stored.scenario_hash != scenario_hash(sc):
            raise ScenarioError(
                f"--baseline {where}: scenario {sc.name!r} ({sc.path}) changed since the "
                f"baseline (hash {stored.scenario_hash}, now {scenario_hash(sc)}), so its "
                "metrics are not comparable; rerun with --update-baseline to store a new one"
            )
        if stored.seed != sc.seed:
            raise ScenarioError(
                f"--baseline {where}: scenario {sc.name!r} ran with seed {stored.seed} in the "
                f"baseline, {sc.seed} now; use the same seed or rerun with --update-baseline"
            )

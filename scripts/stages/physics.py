"""Physics plausibility of the ground truth on the humanoid (``sim.plausibility``).

Its thresholds are the check definitions of ``sim.thresholds.CheckConfig``, overridable in the
scenario's ``[physics]`` table; each thresholded value becomes a check row of the run.
"""

from __future__ import annotations

from avatarsim.scripts.results import ThresholdResult
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Threshold
from avatarsim.sim.plausibility import CONTRACT_KEYS, check_humanoid
from avatarsim.sim.report import write_outputs
from avatarsim.sim.thresholds import THRESHOLD_KEYS, CheckConfig

METRICS = {
    key: f"physics check value ({check}); threshold in [physics]"
    for key, check in THRESHOLD_KEYS.items()
}


def config(ctx_or_table: RunContext | dict) -> CheckConfig:
    table = ctx_or_table if isinstance(ctx_or_table, dict) else ctx_or_table.scenario.physics
    return CheckConfig.from_dict(table)


def run(ctx: RunContext) -> None:
    report = check_humanoid(ctx.humanoid, config(ctx))
    for row in report.thresholds:
        ctx.metrics[row["name"]] = float(row["value"])
        ctx.checks.append(
            ThresholdResult(row["name"], float(row["value"]), Threshold(max=row["threshold"]))
        )
    ctx.info["physics"] = {k: report.values.get(k) for k in CONTRACT_KEYS} | {
        "passed": report.passed
    }
    for key, path in write_outputs(report, ctx.out_dir / "physics").items():
        ctx.output(f"physics_{key}", path)

"""Physics tracking of the ground truth: the MuJoCo humanoid follows it under simulation,
root unactuated (``sim.sampling`` search by default, ``sim.tracking`` alone with
``search = false``), for ``[tracking] seconds`` (the clip looped on its gait cycle when
shorter). Writes ``tracking/`` (CSV, JSON, plot)."""

from __future__ import annotations

from scripts.run_context import RunContext
from scripts.scenario import Scenario
from sim.sampling import SearchSettings, timed_tracking
from sim.tracking import looped
from sim.tracking_report import write_outputs

METRICS = {
    "tracking_fell": "1 if the humanoid fell or the search gave up before the end, else 0",
    "tracking_upright_s": "seconds tracked before a fall (all of them if none)",
    "tracking_err_cm_mean": "mean body17 distance from the reference while upright (cm)",
    "tracking_x_real_time": "seconds tracked per second of computation",
}


def metrics_for(scenario: Scenario) -> set[str]:
    return set(METRICS) if scenario.tracking is not None else set()


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.tracking
    if spec is None:
        return
    fps = ctx.motion.fps
    reference = ctx.humanoid.for_tracking()
    qpos = looped(reference.qpos, fps, spec.seconds)
    search = SearchSettings() if spec.search else None
    result, summary = timed_tracking(reference.model, qpos, fps, search)
    upright = summary["duration_s"] if result.fall_time_s is None else result.fall_time_s
    ctx.metrics |= {
        "tracking_fell": float(not summary["completed"]),
        "tracking_upright_s": upright,
        "tracking_err_cm_mean": summary["body17_err_cm_mean"],
        "tracking_x_real_time": summary["x_real_time"],
    }
    ctx.info["tracking"] = summary
    title = f"physics tracking of the ground truth ({summary['mode']})"
    for key, path in write_outputs(result, summary, ctx.out_dir / "tracking", title).items():
        ctx.output(f"tracking_{key}", path)

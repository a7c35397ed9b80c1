"""Physics control of the ground truth: the MuJoCo humanoid follows it under simulation,
root unactuated (the search of ``sim.control.search`` by default, the plain controller with
``search = false``), for ``[control] seconds`` (the clip looped on its gait cycle when
shorter). Writes ``control/`` (CSV, JSON, plot)."""

from __future__ import annotations

from avatarsim.scripts.control_run import timed_control
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Scenario
from avatarsim.sim.control.reference import looped
from avatarsim.sim.control.report import write_outputs
from avatarsim.sim.control.search import SearchSettings

METRICS = {
    "control_fell": "1 if the humanoid fell or the search gave up before the end, else 0",
    "control_upright_s": "seconds followed before a fall (all of them if none)",
    "control_err_cm_mean": "mean body17 distance from the reference while upright (cm)",
    "control_x_real_time": "seconds followed per second of computation",
}


def metrics_for(scenario: Scenario) -> set[str]:
    return set(METRICS) if scenario.control is not None else set()


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.control
    if spec is None:
        return
    fps = ctx.motion.fps
    reference = ctx.humanoid.for_control()
    qpos = looped(reference.qpos, fps, spec.seconds)
    search = SearchSettings() if spec.search else None
    result, summary = timed_control(reference.control_model(), qpos, fps, search)
    upright = summary["duration_s"] if result.fall_time_s is None else result.fall_time_s
    ctx.metrics |= {
        "control_fell": float(not summary["completed"]),
        "control_upright_s": upright,
        "control_err_cm_mean": summary["body17_err_cm_mean"],
        "control_x_real_time": summary["x_real_time"],
    }
    ctx.info["control"] = summary
    title = f"physics control of the ground truth ({summary['mode']})"
    for key, path in write_outputs(result, summary, ctx.out_dir / "control", title).items():
        ctx.output(f"control_{key}", path)

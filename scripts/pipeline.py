"""The scenario runner: motion source -> humanoid -> kinematic replay -> pictures -> checks.

Each stage is a function ``stage(ctx) -> None`` that reads and extends the :class:`RunContext`
(``ctx.metrics`` for thresholded numbers, ``ctx.outputs`` for files written). A later
capability (devices, synthesis, physics checks) adds a stage and declares its metrics in
``METRICS`` so thresholds naming them are validated before anything runs.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import imageio.v3 as iio
import mujoco
import numpy as np
from rich.console import Console

from avatar_models.body import build_body
from avatar_models.formats import load_motion, save_motion
from avatar_models.generator import ACTIVITIES, generate, sample_subject
from avatar_models.motion import Motion
from scripts.results import CheckResult, junit_xml, versions, write_atomic, write_json
from scripts.scenario import Scenario, ScenarioError
from sim.render import render_frames
from sim.replay import replay_kinematic

DEFAULT_MASS_KG = 75.0

# metric name -> what it measures (unit in the name). Thresholds may name only these.
METRICS: dict[str, str] = {
    "replay_error_mm_max": "max distance between MuJoCo's replayed joints and the motion's FK",
    "penetration_cm_p95": "95th percentile over frames of MuJoCo's deepest floor penetration",
    "float_cm_p95": "95th percentile over frames of the lowest body point above the floor",
    "frames": "number of motion frames",
}


@dataclass
class RunContext:
    scenario: Scenario
    out_dir: Path
    console: Console
    motion: Motion | None = None
    model: mujoco.MjModel | None = None
    qpos: np.ndarray | None = None
    metrics: dict[str, float] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)

    def output(self, key: str, path: Path) -> None:
        self.outputs[key] = str(path.relative_to(self.out_dir))


def motion_stage(ctx: RunContext) -> None:
    spec = ctx.scenario.motion
    if spec.source == "builtin":
        if spec.activity not in ACTIVITIES:
            raise ScenarioError(
                f"motion.activity {spec.activity!r} unknown; built-in: {', '.join(ACTIVITIES)}"
            )
        rng = np.random.default_rng(ctx.scenario.seed)
        subject = sample_subject(rng)
        chosen = {"height_m": spec.height_m, "style": spec.style}
        subject = dataclasses.replace(subject, **{k: v for k, v in chosen.items() if v is not None})
        motion = generate(
            spec.activity, subject, duration_s=spec.duration_s, fps=spec.fps, seed=ctx.scenario.seed
        )
    else:
        options = {} if spec.unit is None else {"unit": spec.unit}
        motion = load_motion(spec.source, **options)
        if abs(motion.fps - spec.fps) > 1e-9:
            motion = motion.resample(spec.fps)
        motion = motion[: max(1, int(round(spec.duration_s * motion.fps)) + 1)]
    ctx.motion = motion
    ctx.metrics["frames"] = float(motion.n_frames)
    ctx.info["motion"] = {
        "source": spec.source,
        "activity": motion.meta.get(
            "activity", spec.activity if spec.source == "builtin" else None
        ),
        "joints": motion.skeleton.n_joints,
        "fps": motion.fps,
        "frames": motion.n_frames,
        "duration_s": motion.duration_s,
        "subject": motion.meta.get("subject"),
    }
    ctx.output("motion_bvh", save_motion(motion, ctx.out_dir / "motion.bvh"))


def body_stage(ctx: RunContext) -> None:
    spec = ctx.scenario.body
    mass_kg = spec.mass_kg or (ctx.motion.meta.get("subject") or {}).get("mass_kg", DEFAULT_MASS_KG)
    body = build_body(ctx.motion.skeleton, height_m=spec.height_m, mass_kg=mass_kg)
    xml = body.to_mjcf()
    ctx.model = mujoco.MjModel.from_xml_string(xml)
    ctx.qpos = body.qpos_from_motion(ctx.motion)
    ctx.info["body"] = {"mass_kg": mass_kg, "nq": ctx.model.nq, "nbody": ctx.model.nbody}
    ctx.output("mjcf", write_atomic(ctx.out_dir / "humanoid.xml", xml))


def replay_stage(ctx: RunContext) -> None:
    trace = replay_kinematic(ctx.model, ctx.qpos)
    sk = ctx.motion.skeleton
    fk = ctx.motion.global_positions()
    names = [
        mujoco.mj_id2name(ctx.model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(ctx.model.nbody)
    ]
    pairs = [(sk.index(n), b) for b, n in enumerate(names) if n in sk]
    joint_idx, body_idx = np.array(pairs).T
    err = np.linalg.norm(trace.body_pos[:, body_idx] - fk[:, joint_idx], axis=-1)
    ctx.metrics["replay_error_mm_max"] = float(err.max() * 1000.0)
    ctx.metrics["penetration_cm_p95"] = float(np.percentile(trace.floor_penetration, 95) * 100.0)
    ctx.metrics["float_cm_p95"] = float(
        np.percentile(np.maximum(trace.lowest_point, 0.0), 95) * 100.0
    )
    ctx.info["replay"] = {"joints_compared": len(pairs)}


def picture_stage(ctx: RunContext) -> None:
    spec = ctx.scenario.report
    n = ctx.qpos.shape[0]
    strip_ids = np.linspace(0, n - 1, spec.picture_frames).round().astype(int)
    frames = render_frames(ctx.model, ctx.qpos, strip_ids)
    ctx.output(
        "strip_png",
        write_atomic(
            ctx.out_dir / "strip.png", iio.imwrite("<bytes>", np.hstack(frames), extension=".png")
        ),
    )
    if spec.gif:
        step = max(1, int(round(ctx.motion.fps / spec.gif_fps)))
        gif_frames = render_frames(
            ctx.model, ctx.qpos, np.arange(0, n, step), width=240, height=300
        )
        gif = iio.imwrite(
            "<bytes>", gif_frames, extension=".gif", duration=1000.0 / spec.gif_fps, loop=0
        )
        ctx.output("motion_gif", write_atomic(ctx.out_dir / "motion.gif", gif))


STAGES: list[tuple[str, Callable[[RunContext], None]]] = [
    ("motion", motion_stage),
    ("body", body_stage),
    ("replay", replay_stage),
    ("pictures", picture_stage),
]


def validate_thresholds(scenario: Scenario) -> None:
    unknown = sorted(set(scenario.thresholds) - set(METRICS))
    if unknown:
        raise ScenarioError(
            f"thresholds name unknown metric(s) {unknown}; known: {sorted(METRICS)}"
        )


def run_scenario(
    scenario: Scenario, out_dir: Path, console: Console | None = None
) -> dict[str, Any]:
    """Run every stage, evaluate thresholds, write results.json and junit.xml into ``out_dir``."""
    validate_thresholds(scenario)
    console = console or Console(stderr=True)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ctx = RunContext(scenario, out_dir, console)
    timings: dict[str, float] = {}
    start = time.perf_counter()
    for name, stage in STAGES:
        t0 = time.perf_counter()
        with console.status(f"[bold]{scenario.name}[/]: {name}"):
            stage(ctx)
        timings[name] = round(time.perf_counter() - t0, 3)
        console.log(f"{name} done in {timings[name]:.2f} s")
    checks = [CheckResult(k, ctx.metrics[k], t) for k, t in scenario.thresholds.items()]
    passed = all(c.passed for c in checks)
    results = {
        "scenario": scenario.name,
        "scenario_path": scenario.path,
        "passed": passed,
        "checks": [c.to_json() for c in checks],
        "metrics": ctx.metrics,
        "seeds": {"scenario": scenario.seed},
        **ctx.info,
        "outputs": {**ctx.outputs, "results_json": "results.json", "junit_xml": "junit.xml"},
        "timings_s": timings,
        "versions": versions(),
    }
    write_atomic(
        out_dir / "junit.xml", junit_xml(scenario.name, checks, time.perf_counter() - start)
    )
    write_json(out_dir / "results.json", results)
    return results

"""``avatarsim eval avatargo``: AvatarGo's simulated user study (§4-5), exact against fixed
offsets, on built-in motion or real mocap, with the physics checks of every output.

Per test motion one simulated user (:func:`synthesis.avatargo.study.sample_user`: avatar
legs and arms +-10 %, trackers strapped up to 5 cm off at any rotation, any facing) wearing
the six devices with the scenarios' realistic VR noise. A real clip is first put on its
humanoid (:func:`sim.humanoid.humanoid_for`: its own rig, or the avatar rig it is
retargeted onto), so that the user stands on a rig with a standing rest pose. Composed here
because it needs both ``sim`` (physics) and ``synthesis`` (the method).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from scripts.stages.devices import REALISTIC_NOISE
from sim.humanoid import humanoid_for
from sim.plausibility import CONTRACT_KEYS, check_humanoid
from sim.thresholds import CheckConfig
from synthesis.avatargo.study import EFFECTORS, sample_user, study_run
from synthesis.avatargo.synthesizer import ANALYTIC
from synthesis.evaluate import Trial

VARIANTS = ("exact", "fixed")
BUILTIN_ACTIVITIES = ("wave", "box", "walk")
"""Built-in motions of the study: standing (the leg artefact shows), arms busy, and walking."""


def run_user(trial: Trial, duration_s: float, checks: CheckConfig, solver: str = ANALYTIC) -> dict:
    """One trial's row: the user, and per variant the study's scores and physics values,
    AvatarGo's per-tick IK by ``solver`` (:data:`~synthesis.avatargo.synthesizer.SOLVERS`)."""
    truth = trial.motion
    frames = int(round(duration_s * truth.fps)) + 1
    truth = humanoid_for(truth[: min(frames, truth.n_frames)]).motion
    user = sample_user(trial.seed, truth.skeleton)
    result = study_run(truth, user, REALISTIC_NOISE, solver=solver)
    row = {"trial": trial.name, "class": trial.cls, "user": result["user"]}
    for kind in VARIANTS:
        physics = check_humanoid(humanoid_for(result["motions"][kind]), checks).values
        row[kind] = {**result[kind], "physics": {k: float(physics[k]) for k in CONTRACT_KEYS}}
    return row


def flatten(scores: dict) -> dict[str, float]:
    """A variant's scores as one level of ``name: value``."""
    out = {}
    for key, value in scores.items():
        if isinstance(value, dict):
            out.update({f"{key}.{k}": v for k, v in value.items()})
        elif key not in ("frames", "standing_frames"):
            out[key] = value
    return out


def summarise(rows: Sequence[dict]) -> dict:
    """Means over users per variant, and how often exact beat fixed on the leg artefact
    (among the users whose avatar legs differ and who stand at some point)."""
    summary = {}
    for kind in VARIANTS:
        flat = [flatten(r[kind]) for r in rows]
        keys = [k for k in flat[0] if all(k in f for f in flat)]
        summary[kind] = {k: float(np.nanmean([f[k] for f in flat])) for k in keys}
    legs = [
        r
        for r in rows
        if abs(r["user"]["leg_scale"] - 1.0) > 0.01 and r["exact"]["standing_frames"] > 0
    ]
    summary["exact_beats_fixed_knee"] = (
        f"{sum(r['exact']['knee_err_deg'] < r['fixed']['knee_err_deg'] for r in legs)}/{len(legs)}"
    )
    return summary


def run_avatargo_eval(
    trials: Sequence[Trial],
    duration_s: float,
    checks: CheckConfig | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    solver: str = ANALYTIC,
) -> dict:
    """The study over ``trials`` (one simulated user each), first ``duration_s`` of each,
    with AvatarGo's per-tick IK by ``solver``."""
    checks = checks or CheckConfig()
    rows = []
    for i, trial in enumerate(trials):
        rows.append(run_user(trial, duration_s, checks, solver))
        if progress is not None:
            progress(i + 1, len(trials), trial.name)
    return {"method": "avatargo", "solver": solver, "users": rows, "overall": summarise(rows)}


def write_plot(results: dict, path: Path) -> Path:
    """Bars of exact against fixed: end-effector errors, knee error, palm distance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    overall = results["overall"]
    keys = [f"effector_err_cm.{k}" for k in EFFECTORS] + ["knee_err_deg", "palm_cm"]
    labels = [*EFFECTORS, "knee (deg)", "palm"]
    x = np.arange(len(keys))
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    for i, kind in enumerate(VARIANTS):
        ax.bar(x + 0.4 * i - 0.2, [overall[kind][k] for k in keys], 0.4, label=f"{kind} offsets")
    ax.set_xticks(x, labels)
    ax.set_ylabel("cm (knee: degrees)")
    ax.set_title(f"AvatarGo, {len(results['users'])} simulated users: exact vs fixed offsets")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

"""``avatarsim eval avatargo-study``: AvatarGo's simulated user study (§4-5), exact against
fixed offsets, on the paper's tasks (built-in motion) or real mocap, with the physics checks of
every output.

The tasks are the paper's (§4, :data:`TASKS`): T1 arms (from a T-pose the controllers move in
towards the body and out again, the generator's ``arms``), T2 squats (``squat``) and T3 free
movement (here ``walk``, ``box`` and ``kick``). Per test motion one simulated user
(:func:`synthesis.avatargo.study.sample_user`: avatar legs and arms within the limb spread,
trackers strapped by a person, any facing) wearing the six devices with the scenarios'
realistic VR noise, scored against the user's own joints in every condition of
:data:`~synthesis.avatargo.study.VARIANTS`. The paper's result is a questionnaire; ours is
the geometric proxy :data:`~synthesis.avatargo.study.PROXY`. A real clip is first put on its
humanoid (:func:`sim.humanoid.humanoid_for`: its own rig, or the avatar rig it is
retargeted onto), so that the user stands on a rig with a standing rest pose; its task is
its class. Composed here because it needs both ``sim`` (physics) and ``synthesis`` (the
method).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from avatarsim.render_cams.vr.noise import REALISTIC_NOISE
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.plausibility import CONTRACT_KEYS, check_humanoid
from avatarsim.sim.thresholds import CheckConfig
from avatarsim.synthesis.avatargo.study import (
    EFFECTORS,
    LIMB_SPREAD,
    PROXY,
    STRAP_MAX_M,
    STRAP_YAW_MAX_RAD,
    VARIANTS,
    sample_user,
    study_run,
)
from avatarsim.synthesis.avatargo.synthesizer import ANALYTIC, SOLVER_LABELS
from avatarsim.synthesis.evaluate import Trial

TASKS = {"arms": "T1 arms", "squat": "T2 squats", "walk": "T3 free", "box": "T3 free",
         "kick": "T3 free"}  # fmt: skip
"""Built-in activity -> the paper's task (§4: T1 arms, T2 legs (squats), T3 free)."""
BUILTIN_ACTIVITIES = tuple(TASKS)
QUICK_ACTIVITIES = ("arms", "squat", "walk")
"""``--quick``: one activity per task."""


def task_of(trial: Trial) -> str:
    """The paper's task of a built-in activity (:data:`TASKS`), else the trial's class."""
    return TASKS.get(trial.cls, trial.cls)


def run_user(
    trial: Trial,
    duration_s: float,
    checks: CheckConfig,
    solver: str = ANALYTIC,
    limb_spread: float = LIMB_SPREAD,
    strap_yaw_rad: float = STRAP_YAW_MAX_RAD,
) -> dict:
    """One trial's row: the user, and per variant the study's scores and physics values,
    AvatarGo's per-tick IK by ``solver`` (:data:`~synthesis.avatargo.synthesizer.SOLVERS`),
    the user drawn with ``limb_spread`` and ``strap_yaw_rad`` (:func:`sample_user`)."""
    truth = trial.motion
    frames = int(round(duration_s * truth.fps)) + 1
    truth = humanoid_for(truth[: min(frames, truth.n_frames)]).motion
    user = sample_user(trial.seed, truth.skeleton, limb_spread, STRAP_MAX_M, strap_yaw_rad)
    result = study_run(truth, user, REALISTIC_NOISE, solver=solver)
    row = {"trial": trial.name, "class": trial.cls, "task": task_of(trial), "user": result["user"]}
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


def means(scores: Sequence[dict]) -> dict[str, float]:
    """Means over users of the flattened scores (:func:`flatten`) all of them have; NaN
    (a user who never stands) left out."""
    flat = [flatten(s) for s in scores]
    keys = [k for k in flat[0] if all(k in f for f in flat)]
    out = {}
    for k in keys:
        values = np.array([f[k] for f in flat], float)
        out[k] = float(values[np.isfinite(values)].mean()) if np.isfinite(values).any() else np.nan
    return out


def by_task(rows: Sequence[dict]) -> dict[str, dict[str, dict[str, float]]]:
    """``{task: {variant: means}}`` in the order tasks first appear."""
    tasks = dict.fromkeys(r["task"] for r in rows)
    return {
        t: {kind: means([r[kind] for r in rows if r["task"] == t]) for kind in VARIANTS}
        for t in tasks
    }


def summarise(rows: Sequence[dict]) -> dict:
    """Means over users per variant, and how often exact beat fixed on the leg artefact
    (among the users whose avatar legs differ and who stand at some point)."""
    summary = {kind: means([r[kind] for r in rows]) for kind in VARIANTS}
    legs = [
        r
        for r in rows
        if abs(r["user"]["leg_scale"] - 1.0) > 0.01 and r["exact"]["standing_frames"] > 0
    ]
    beats = sum(
        r["exact"]["standing_knee_err_deg"] < r["fixed"]["standing_knee_err_deg"] for r in legs
    )
    summary["exact_beats_fixed_knee"] = f"{beats}/{len(legs)}"
    return summary


def run_avatargo_eval(
    trials: Sequence[Trial],
    duration_s: float,
    checks: CheckConfig | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    solver: str = ANALYTIC,
    limb_spread: float = LIMB_SPREAD,
    strap_yaw_rad: float = STRAP_YAW_MAX_RAD,
) -> dict:
    """The study over ``trials`` (one simulated user each), first ``duration_s`` of each,
    with AvatarGo's per-tick IK by ``solver``, users drawn with ``limb_spread`` and
    ``strap_yaw_rad`` (:func:`run_user`)."""
    checks = checks or CheckConfig()
    rows = []
    for i, trial in enumerate(trials):
        rows.append(run_user(trial, duration_s, checks, solver, limb_spread, strap_yaw_rad))
        if progress is not None:
            progress(i + 1, len(trials), trial.name)
    return {
        "method": "avatargo",
        "solver": solver,
        "solver_label": SOLVER_LABELS[solver],
        "measure": PROXY,
        "reference": "the simulated user's ground-truth joints (the motion the devices sampled)",
        "limb_spread": limb_spread,
        "strap_max_shift_m": STRAP_MAX_M,
        "strap_max_yaw_deg": float(np.degrees(strap_yaw_rad)),
        "users": rows,
        "tasks": by_task(rows),
        "overall": summarise(rows),
    }


def write_plot(results: dict, path: Path) -> Path:
    """Bars of exact against fixed: end-effector errors, knee error, palm distance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    overall = results["overall"]
    keys = [f"effector_err_cm.{k}" for k in EFFECTORS] + ["knee_err_deg", "palm_cm"]
    labels = [*EFFECTORS, "knee (deg)", "palm"]
    x = np.arange(len(keys))
    width = 0.8 / len(VARIANTS)
    fig, ax = plt.subplots(figsize=(8.0, 4.0))
    for i, kind in enumerate(VARIANTS):
        left = x - 0.4 + width * (i + 0.5)
        ax.bar(left, [overall[kind][k] for k in keys], width, label=kind)
    ax.set_xticks(x, labels)
    ax.set_ylabel("cm from the user's joints (knee: degrees)")
    ax.set_title(
        f"AvatarGo, {len(results['users'])} simulated users (geometric proxy, not the SoE)"
    )
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

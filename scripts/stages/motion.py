"""Motion source: the built-in generator or a motion file -> the ground-truth ``Motion``."""

from __future__ import annotations

import dataclasses

import numpy as np

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.formats import load_motion, save_motion
from avatarsim.avatar_models.generator import ACTIVITIES, generate, sample_subject
from avatarsim.avatar_models.measure import check_plausible_height
from avatarsim.scripts.corruption import corrupted
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import MIN_FRAMES, ScenarioError

METRICS = {"frames": "number of motion frames"}


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.motion
    if spec.source == "builtin":
        if spec.activity not in ACTIVITIES:
            raise ScenarioError(
                f"motion.activity {spec.activity!r} unknown; built-in: {', '.join(ACTIVITIES)}"
            )
        subject = sample_subject(np.random.default_rng(ctx.scenario.seed))
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
        if motion.n_frames < MIN_FRAMES:
            raise ScenarioError(
                f"motion {spec.source}: too short: {motion.n_frames} frame(s); a run needs at "
                f"least {MIN_FRAMES} (velocities and accelerations)"
            )
        try:
            check_plausible_height(motion)
        except MotionValueError as exc:
            raise ScenarioError(f"motion {spec.source}: {exc} (motion.unit)") from None
    if spec.corrupt is not None:
        motion = corrupted(motion, spec.corrupt, ctx.scenario.seed)
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
        "corrupt": spec.corrupt,
    }
    ctx.output("motion_bvh", save_motion(motion, ctx.out_dir / "motion.bvh"))

"""Full-body synthesis from the VR stream, its accuracy against the ground truth (body17) and
the physics plausibility of each method's output on the humanoid."""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.generator import generate_library
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.motion import Motion
from avatarsim.render_cams.vr import HEADSET_AND_CONTROLLERS, Attachment
from avatarsim.scripts.method_score import score_method
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Scenario, ScenarioError
from avatarsim.scripts.stages.physics import config as physics_config
from avatarsim.sim.humanoid import Humanoid
from avatarsim.synthesis.base import Synthesizer
from avatarsim.synthesis.coolmoves import build_database
from avatarsim.synthesis.ik_baseline import attachments_on_upright_rig
from avatarsim.synthesis.methods import METHODS, MethodInputs, build
from avatarsim.synthesis.scoring import GROUPS


def method_metrics(method: str) -> dict[str, str]:
    """The metrics (name -> meaning) a run of ``method`` reports."""
    return {
        **{
            f"{method}_err_cm_{g}": f"{method}: mean body17 error of the {g} group (cm)"
            for g in GROUPS
        },
        f"{method}_hand_corr_min": f"{method}: Pearson r of input vs output hands, worse hand",
        f"{method}_skate_cm_s_median": f"{method}: stance foot skating of its output",
        f"{method}_penetration_cm_p95": f"{method}: floor penetration of its output",
    }


METRICS = {name: meaning for m in METHODS for name, meaning in method_metrics(m).items()}


def metrics_for(scenario: Scenario) -> set[str]:
    methods = scenario.synthesis.methods if scenario.synthesis is not None else ()
    return {name for m in methods for name in method_metrics(m)}


def database_takes(ctx: RunContext) -> list[Motion]:
    """Built-in takes of the scenario's activity by other subjects (not the user)."""
    spec = ctx.scenario.synthesis
    # A seed stream apart from the user's (the user is the first subject of the scenario seed).
    seed = int(np.random.SeedSequence([ctx.scenario.seed, 1]).generate_state(1)[0])
    activity = ctx.info["motion"]["activity"] or "walk"
    return generate_library(
        (activity,), spec.database_subjects, spec.database_duration_s, 90.0, seed
    )


def ik_calibration(ctx: RunContext) -> list[Attachment] | None:
    """The VR devices' attachments on the humanoid's rig: None (the nominal ones) for the
    truth's own rig; on a rig retargeted from a foreign one, the attachments the stream was
    sampled with, turned into the upright rig's joint frames."""
    if not ctx.humanoid.retargeted:
        return None
    offsets = ctx.vr_stream.meta["offsets"]
    measured = [Attachment(**offsets[device]) for device in HEADSET_AND_CONTROLLERS]
    return attachments_on_upright_rig(measured, ctx.motion.skeleton)


def method_inputs(ctx: RunContext, user_height_m: float) -> MethodInputs:
    """The registry's inputs for this scenario: a database of :func:`database_takes` (built
    once, for every CoolMoves variant), and the humanoid's rig (the ground truth's own, or the
    avatar rig a foreign rig was retargeted onto) for the IK baseline, so that errors
    compare like for like."""
    return MethodInputs(
        database_factory=lambda: build_database(database_takes(ctx)),
        user_height_m=user_height_m,
        rig=ctx.humanoid.body.skeleton,
        calibration=ik_calibration(ctx),
        coolmoves={"foot_contact": ctx.scenario.synthesis.foot_contact},
        walk_in=ctx.walk_in,
        kinect=ctx.kinect_stream,
        fisheye=ctx.fisheye_keypoints,
    )


def make_synthesizer(method: str, inputs: MethodInputs) -> Synthesizer:
    if method not in METHODS:
        raise ScenarioError(f"unknown synthesis method {method!r}; known: {', '.join(METHODS)}")
    return build(method, inputs)


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.synthesis
    if spec is None:
        return
    stream = ctx.vr_stream
    subject = ctx.motion.meta.get("subject")
    user_height_m = (subject.get("height_m") if isinstance(subject, dict) else None) or (
        standing_height(ctx.motion)
    )
    checks = physics_config(ctx)  # the scenario's [physics] settings, as for the ground truth
    outputs: dict[str, Humanoid] = {}
    inputs = method_inputs(ctx, user_height_m)
    for method in spec.methods:
        synth = make_synthesizer(method, inputs)
        result = score_method(synth, ctx.motion, stream, checks)
        outputs[method] = result.humanoid
        score = result.score
        for group, value in score.err_cm.items():
            ctx.metrics[f"{method}_err_cm_{group}"] = value
        ctx.metrics[f"{method}_hand_corr_min"] = min(score.hand_corr.values())
        for key in ("skate_cm_s_median", "penetration_cm_p95"):
            ctx.metrics[f"{method}_{key}"] = result.physics[key]
        ctx.info.setdefault("synthesis", {})[method] = {
            "frames": score.frames,
            "hand_corr": score.hand_corr,
            "err_cm": score.err_cm,
        }
    ctx.synthesised = outputs

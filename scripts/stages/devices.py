"""Simulated tracking of the ground truth: VR headset and controllers (+ Vive trackers) at 90 Hz,
and, with ``[devices] kinect``, a Kinect skeleton stream at 30 Hz (MoveBox's input)."""

from __future__ import annotations

import numpy as np

from avatarsim.render_cams.kinect import Kinect, TrackingState
from avatarsim.render_cams.vr import FULL_BODY, HEADSET_AND_CONTROLLERS, REALISTIC_NOISE, VRSetup
from avatarsim.render_cams.vr.dropouts import Dropouts
from avatarsim.render_cams.vr.noise import Latency, PositionJitter
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Scenario
from avatarsim.synthesis.avatargo.walk_in import walk_in

METRICS = {
    "vr_valid_frac": "share of valid VR samples over all devices",
    "kinect_tracked_frac": "share of Tracked Kinect joint samples",
}


def metrics_for(scenario: Scenario) -> set[str]:
    spec = scenario.devices
    if spec is None:
        return set()
    return {k for k, on in (("vr_valid_frac", spec.vr), ("kinect_tracked_frac", spec.kinect)) if on}


def setup(ctx: RunContext) -> VRSetup:
    spec = ctx.scenario.devices
    devices = FULL_BODY if spec.trackers else HEADSET_AND_CONTROLLERS
    noise = REALISTIC_NOISE if spec.noise == "realistic" else ()
    sweep = (
        (spec.latency_s, lambda: Latency(seconds=spec.latency_s)),
        (spec.jitter_m, lambda: PositionJitter(sigma_m=spec.jitter_m)),
        (spec.dropouts_per_s, lambda: Dropouts(bursts_per_s=spec.dropouts_per_s)),
    )
    noise += tuple(model() for amount, model in sweep if amount > 0)
    return VRSetup(devices=devices, noise=noise)


def record_kinect(ctx: RunContext) -> None:
    """The Kinect skeleton stream of the motion on the humanoid (``[devices] kinect``), from
    ``[devices] kinect_skeleton``: tracked on the rendered depth, or the oracle (not a
    sensor, labelled so in the run's info)."""
    spec = ctx.scenario.devices
    kinect = Kinect(spec.kinect, skeleton=spec.kinect_skeleton)
    stream = kinect.sample(ctx.humanoid.motion, ctx.scenario.seed, ctx.humanoid.body).skeleton
    ctx.kinect_stream = stream
    ctx.metrics["kinect_tracked_frac"] = float(np.mean(stream.states == TrackingState.TRACKED))
    ctx.info.setdefault("devices", {})["kinect"] = {
        "device": spec.kinect,
        "rig": stream.rig,
        "samples": stream.n_samples,
        "skeleton": stream.meta["skeleton"],
        **{k: stream.meta[k] for k in ("skeleton_note",) if k in stream.meta},
    }


def run(ctx: RunContext) -> None:
    if ctx.scenario.devices is None:
        return
    if ctx.scenario.devices.kinect:
        record_kinect(ctx)
    if not ctx.scenario.devices.vr:
        return
    vr = setup(ctx)
    stream = vr.sample(ctx.motion, seed=ctx.scenario.seed)
    ctx.vr_stream = stream
    if ctx.scenario.devices.trackers:  # AvatarGo's walk-in T-pose, with the same devices
        ctx.walk_in = walk_in(vr, ctx.motion, ctx.scenario.seed)
    ctx.metrics["vr_valid_frac"] = float(stream.valid.mean())
    ctx.info.setdefault("devices", {}).update(
        {
            "vr": list(stream.device_names),
            "rate_hz": vr.rate_hz,
            "samples": int(stream.timestamps.size),
            "noise": ctx.scenario.devices.noise,
        }
    )
    ctx.output("vr_stream", stream.to_npz(ctx.out_dir / "vr_stream.npz"))
    if ctx.scenario.devices.fisheye:
        from avatarsim.scripts.controllerpose.recording import keypoint_recording

        ctx.fisheye_keypoints = keypoint_recording(ctx.humanoid, ctx.scenario.seed)
        ctx.info["devices"]["fisheye_frames"] = int(ctx.fisheye_keypoints.time.size)

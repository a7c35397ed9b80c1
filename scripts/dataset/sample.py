"""One sample: a motion window on the humanoid, recorded by one device set.

:func:`make_sample` returns the sample's arrays (WebDataset entries ``<key>.<name>.npy``)
and its JSON (``<key>.json``): ground truth ``body17`` (T, 17, 3) world metres, its joint
angles ``body17_angles`` (T, 43) (ControllerPose's parameterisation,
:mod:`avatar_models.body17_angles`: hip as root, world frame) and ``qpos`` (T, nq) of the
humanoid (:func:`sim.humanoid.humanoid_for`; a foreign rig is retargeted and
its residual recorded), then the channels of :mod:`.channels` the device set asks for. The
JSON holds the split and group, the subject's parameters, the provenance (source, clip,
window start, every seed, package version, config hash) and each channel's description.

The devices' seed is split with ``SeedSequence`` into one stream per random channel, in a
fixed order (VR, Kinect, fisheye detector, fisheye images), so that adding a channel later
leaves the others' draws unchanged. Images and depth are entries of their own
(``<key>.fisheye_image.{camera}.{n:04d}.jpg``, ``<key>.kinect_depth.{n:04d}.png``): bytes in
``arrays``, encoded files.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models.body17_angles import angles_from_positions
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.scripts.dataset.channels import (
    f32,
    fisheye_channel,
    fisheye_image_channel,
    kinect_channel,
    physics_channel,
    vr_channel,
)
from avatarsim.scripts.dataset.config import DatasetConfig
from avatarsim.scripts.dataset.motion_source import window_motion
from avatarsim.scripts.dataset.plan import SampleSpec, subject_seed
from avatarsim.sim.humanoid import humanoid_for

SAMPLE_SCHEMA = 1


def package_version() -> str:
    try:
        return metadata.version("avatarsim")
    except metadata.PackageNotFoundError:
        return "unknown"


def channel_seeds(seed: int) -> dict[str, int]:
    """The random channels' seeds from the sample's devices seed (module docstring)."""
    names = ("vr", "kinect", "fisheye", "images")  # appended only: spawn(n)'s first children stay
    streams = np.random.SeedSequence(seed).spawn(len(names))
    return {name: int(s.generate_state(1)[0]) for name, s in zip(names, streams, strict=True)}


def make_sample(
    config: DatasetConfig, spec: SampleSpec, config_hash: str
) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """The arrays and JSON of sample ``spec`` (module docstring)."""
    window = spec.window
    devices = next(d for d in config.devices if d.name == spec.devices)
    motion = window_motion(config, window)
    humanoid = humanoid_for(motion)
    seeds = channel_seeds(spec.seed)
    body17 = body17_positions(humanoid.motion)
    arrays = {
        "body17": f32(body17),
        "body17_angles": f32(angles_from_positions(body17)[0]),
        "qpos": f32(humanoid.qpos),
    }
    channels: dict[str, Any] = {}
    if devices.vr:
        arrays_vr, channels["vr"] = vr_channel(humanoid, devices, seeds["vr"])
        arrays |= arrays_vr
    if devices.fisheye:
        arrays_fisheye, channels["fisheye"] = fisheye_channel(humanoid, seeds["fisheye"])
        arrays |= arrays_fisheye
    if devices.fisheye_images != "none":
        arrays_images, channels["fisheye_images"] = fisheye_image_channel(
            humanoid, devices, seeds["images"]
        )
        arrays |= arrays_images
    if devices.kinect != "none":
        arrays_kinect, channels["kinect"] = kinect_channel(humanoid, devices, seeds["kinect"])
        arrays |= arrays_kinect
    if devices.physics:
        arrays_physics, channels["physics"] = physics_channel(humanoid)
        arrays |= arrays_physics
    subject = motion.meta.get("subject")
    meta = {
        "schema_version": SAMPLE_SCHEMA,
        "key": spec.key,
        "index": spec.index,
        "split": spec.split,
        "group": window.group,
        "devices": spec.devices,
        "frames": int(humanoid.motion.n_frames),
        "fps": float(humanoid.motion.fps),
        "activity": window.activity,
        "subject": subject if isinstance(subject, dict) else {"label": subject},
        "body": humanoid.summary(),
        "channels": channels,
        "provenance": {
            "source": window.kind,
            "source_index": window.source,
            "clip": Path(window.clip).name if window.clip else None,
            "window_repeat": window.repeat,
            "window_start_frame": motion.meta["window"]["start_frame"],
            "seeds": {
                "config": config.seed,
                "window": window.seed,
                "devices": spec.seed,
                **({"subject": subject_seed(config, window)} if window.kind == "builtin" else {}),
                **seeds,
            },
            "package_version": package_version(),
            "config_hash": config_hash,
        },
        "arrays": sorted(arrays),
    }
    return arrays, meta
